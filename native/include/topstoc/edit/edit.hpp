// Topology editing on the caller's arrays (thesis 4.2.2, docs/design.md §4.5): delete faces, cut
// along a closed edge loop. Hole filling is in fill_holes.hpp, handle removal (cut + fill) in
// remove_handle.hpp; all of them return an EditResult.
//
// Every edit leaves its input untouched and returns new arrays together with maps back to the
// input, so that UVs, colours, materials and vertex groups carry over on everything the edit did
// not create: vertex_source for per-vertex data, face_source for per-face data, corner_source for
// per-corner data (a triangle that comes from an input triangle keeps that triangle's corner
// order, so its corner data copies over unchanged).
#pragma once

#include <cstdint>
#include <vector>

#include "topstoc/edit/hole_triangulation.hpp"

namespace topstoc {

/// One filled hole.
struct FilledHole {
  int32_t hole = -1;                 ///< index of the hole in the request
  std::vector<int32_t> boundary;     ///< its vertices (result ids), in the patch's orientation
  int32_t first_triangle = 0;        ///< the patch is triangles [first, first + count) of the result
  int32_t num_triangles = 0;
  int32_t first_vertex = 0;          ///< vertices added by the patch: [first, first + count)
  int32_t num_vertices = 0;
  FillMethod method = FillMethod::Planar;
  double normal[3] = {0, 0, 0};      ///< plane normal (planar) or the boundary's Newell normal
  bool refined = false;              ///< refined towards the surrounding edge length
  bool faired = false;               ///< and faired (see FillOptions)
};

/// The copies of a cut loop on one side: a cycle (closed) or, where the loop touched the mesh
/// boundary, a path. Oriented like a boundary loop: the surface is on the left, i.e. the one
/// triangle at each of its edges runs along it in the same direction.
struct CutSide {
  std::vector<int32_t> vertices;
  bool closed = true;
};

struct EditResult {
  std::vector<double> vertices;       ///< 3 per vertex (positions)
  std::vector<int32_t> triangles;     ///< 3 per triangle
  std::vector<int32_t> vertex_source; ///< per vertex: the input vertex it copies, -1 if created
  std::vector<int32_t> face_source;   ///< per triangle: its input triangle, -1 if created
  /// Per corner (3 per triangle): the input corner 3 f + c whose per-corner data it takes, -1 if
  /// none. Patch corners at existing vertices take a corner of a triangle next to the hole.
  std::vector<int32_t> corner_source;
  std::vector<CutSide> cut_sides;     ///< cut_along_loop and remove_handle
  std::vector<FilledHole> patches;    ///< fill_holes and remove_handle
};

/// Deletes the triangles listed in `faces` (repeats allowed) and the vertices that only they
/// used; vertices that were already isolated stay. Kept vertices and triangles keep their
/// relative order. Triangles with a repeated vertex are allowed (this is how to remove them).
/// Throws std::invalid_argument for an index out of range.
EditResult delete_faces(const double* positions, int32_t num_vertices, const int32_t* triangles, int64_t num_triangles,
                        const int32_t* faces, int64_t num_faces);

/// Cuts the surface open along the closed edge loop v0, v1, ..., v(k-1) (edges v(i) v(i+1) and
/// v(k-1) v0): every loop vertex is split into one copy per sector of its triangles between the
/// loop's edges, so the loop becomes two boundary loops (one for a one-sided loop, as on a
/// Moebius band). Vertex ids and positions are kept; the copies are appended. Works for handle
/// and tunnel loops and any simple closed cycle of edges; a loop vertex may lie on the mesh
/// boundary (its copies then join that boundary).
/// Throws std::invalid_argument naming the problem: fewer than 3 vertices, a repeated vertex, two
/// consecutive vertices not joined by an edge, a loop edge on the boundary or shared by more
/// than two triangles, a non-manifold loop vertex, a triangle with a repeated vertex.
EditResult cut_along_loop(const double* positions, int32_t num_vertices, const int32_t* triangles,
                          int64_t num_triangles, const int32_t* loop, int32_t loop_size);

}  // namespace topstoc
