// Pinched vertices in the final output check (verify.cpp): the fans of the input at each
// pinched vertex compared with the fans of its output vertex.
//
// A pinched vertex joins several fans of triangles (a bowtie's centre, two spheres touching at
// a point). Counting edges, vertices and loops per component cannot see a fan that was lost or
// merged there (a collapse that deletes a bowtie's wing keeps every count), so each input fan
// must still be a fan of the output vertex: as many fans, each open or closed as before, each
// on the same sheet. Sheets are the pieces the surface falls into when every pinched vertex is
// split, one copy per fan (triangles joined across edges with exactly two triangles); an output
// triangle lies on the input sheet its corners' input vertices have in common.
#pragma once

#include <cstdint>
#include <vector>

#include "topstoc/core/mesh.hpp"

namespace topstoc {

struct PinchedVertices {
  /// Per input vertex: several fans, and every edge at it has one or two triangles, oriented
  /// consistently (what Mesh's report counts as pinched, orientation checked too).
  std::vector<uint8_t> pinched;
  /// Per component: at least one pinched vertex, and every other vertex manifold (one oriented
  /// fan, no non-manifold edge): a surface but for its pinches, checked as one.
  std::vector<uint8_t> pinched_surface;
  int32_t count = 0;
};

/// The pinched vertices of the input (empty vectors when there are none, the usual case).
PinchedVertices find_pinched_vertices(const Mesh& mesh);

/// Sheet of every input face: faces joined across edges with exactly two faces, named by the
/// lowest face of each sheet.
std::vector<int32_t> face_sheets(const Mesh& mesh);

struct Fan {
  int32_t sheet;  ///< the sheet its triangles lie on
  bool closed;    ///< it goes all around the vertex (no edge at the vertex with one triangle)
};

/// The fans of input vertex v (pinched or not; no edge at it with three triangles or more).
std::vector<Fan> input_fans(const Mesh& mesh, const std::vector<int32_t>& face_sheet, int32_t v);

/// Boundary loops per component, counted as the output check counts them: boundary edges
/// (one triangle) joined at shared vertices, so two loops touching at a pinch count once.
std::vector<int32_t> boundary_edge_groups(const Mesh& mesh);

/// How many pinched input vertices lack an output vertex whose fans match theirs one to one
/// (count, open or closed, sheet). kept: input vertex (internal id) of each output vertex;
/// triangles: 3 output vertex ids each (triangles with a repeated corner are ignored).
int32_t changed_pinched_fans(const Mesh& mesh, const PinchedVertices& pinched, const std::vector<int32_t>& kept,
                             const std::vector<int32_t>& triangles);

}  // namespace topstoc
