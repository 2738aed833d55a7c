// Tetrahedralization of the inside and the outside of a closed surface with TetGen
// (thesis 3.2.4 step 1; Dey, Li, Sun 2007).
//
// The surface is put in a box 10 % larger than its bounding box and the whole is handed to
// TetGen as a piecewise linear complex with the surface kept as it is ("pYQO0": no Steiner
// points on the surface, so every surface triangle is a face of the result). Tetrahedra are
// then told apart by a flood fill from the box that never crosses a surface triangle:
// reached ones lie outside, the rest inside. This needs no seed point and no winding numbers.
//
// TetGen sees each surface vertex moved by a fixed pseudo-random amount of at most
// kTetgenPerturbation times its shortest edge: on flat plates and exact circles its exact
// arithmetic otherwise dominates. Only the tetrahedra's connectivity is used, with the surface's
// own positions; a surface with parts that close would be changed, but TetGen refuses such a
// perturbed input and the exact positions are tried.
//
// TetGen 1.5 crashes its process when it rejects an input (it frees its memory twice), so on
// POSIX systems it runs in a forked child process that hands the result back through a pipe;
// a rejection becomes a TetgenRefused exception, and cancelling kills the child. A surface that
// intersects itself is refused before TetGen sees it, naming two crossing triangles.
#pragma once

#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "topstoc/core/progress.hpp"

namespace topstoc {

/// TetGen could not tetrahedralize the surface; what() says why (self-intersection, ...).
class TetgenRefused : public std::invalid_argument {
 public:
  TetgenRefused(int code, const std::string& why, std::vector<int32_t> vertices = {})
      : std::invalid_argument(why), code_(code), vertices_(std::move(vertices)) {}
  int code() const { return code_; }  ///< TetGen's exit code (3 = self-intersection), 0 if ours
  /// Surface vertex ids of the triangles TetGen named (3 per triangle; often two triangles).
  const std::vector<int32_t>& vertices() const { return vertices_; }

 private:
  int code_;
  std::vector<int32_t> vertices_;
};

struct TetMesh {
  std::vector<double> points;   ///< 3 per point: the surface's vertices (same ids), then box corners and Steiner points
  std::vector<int32_t> tets;    ///< 4 point ids per tetrahedron
  std::vector<uint8_t> inside;  ///< per tetrahedron: 1 inside the surface, 0 between the surface and the box
  std::vector<int32_t> faces;   ///< 3 point ids (increasing) per distinct triangle of the tetrahedra
  std::vector<int32_t> tet_faces;  ///< 4 per tetrahedron: its faces
  std::vector<int32_t> surface_face;  ///< per surface triangle (input order): its face id
  int32_t num_surface_points = 0;
  bool perturbed = false;       ///< TetGen ran on the perturbed positions (false: it refused them)
  double seconds_check = 0.0;   ///< spent checking for self-intersections before TetGen
  int32_t num_points() const { return int32_t(points.size() / 3); }
  int32_t num_tets() const { return int32_t(tets.size() / 4); }
  int32_t num_faces() const { return int32_t(faces.size() / 3); }
};

/// Largest move of a vertex for TetGen, as a fraction of its shortest edge.
constexpr double kTetgenPerturbation = 1e-7;

/// The positions TetGen is given: each coordinate moved by a fixed pseudo-random amount (a
/// function of its index) of at most kTetgenPerturbation times the vertex's shortest edge.
std::vector<double> tetgen_perturbation(const double* positions, int32_t num_vertices, const int32_t* triangles,
                                        int32_t num_triangles);

/// Tetrahedralizes the inside and the outside of the closed surface (num_vertices positions,
/// num_triangles triangles of vertex ids; every vertex used). Throws TetgenRefused when TetGen
/// rejects it or the result does not keep every surface triangle with one tetrahedron on each side;
/// Cancelled when progress says stop.
TetMesh tetrahedralize_surface(const double* positions, int32_t num_vertices, const int32_t* triangles,
                               int32_t num_triangles, Progress* progress = nullptr);

}  // namespace topstoc
