// How far a run of collapses left the surface from the input, both ways, sampled at points of
// each surface and found with a search structure: what the max-aware refinement
// (refine.hpp, RefineParams::max_aware) weighs its second run by and chooses its result by.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "decimate/collapser.hpp"
#include "topstoc/core/mesh.hpp"
#include "topstoc/distance/hausdorff.hpp"

namespace topstoc {

/// Every step-th input triangle (1: all of them) over the input's vertices in the collapses'
/// normalised coordinates: what the distance passes and the fit (tiny_fit.hpp) measure against.
std::shared_ptr<const Surface> normalised_input(const Mesh& mesh, const Collapser& collapser, int64_t step);

/// The whole input (normalised_input with step 1), with each input vertex's area.
struct InputSurface {
  InputSurface(const Mesh& mesh, std::shared_ptr<const Surface> whole);
  std::shared_ptr<const Surface> surface;
  std::vector<double> area;  ///< per input vertex: a third of its triangles' areas
};

struct Deviation {
  /// Per vertex the collapses started from: the squared distance (normalised coordinates) of
  /// the farthest point found around it, from the input to the surface or back.
  std::vector<double> vertex2;
  double top2 = 0.0;    ///< the largest of them
  double mean = 0.0;    ///< mean distance from the input, its vertices weighted by their areas
  double back_mean = 0.0;  ///< mean distance to the input from the surface's points, by area
  int32_t faces = 0;     ///< live triangles
  int32_t vertices = 0;  ///< live vertices
  /// False when the measure stopped early (surface_deviation's rival): vertex2 and top2 then
  /// hold only what the input's vertices found.
  bool complete = true;
};

/// What a run must stay within to be chosen over the best run so far: no point farther than
/// top2 (squared), a mean of at most `mean`.
struct Rival {
  double top2 = 0.0;
  double mean = 0.0;
};

/// From the input: each input vertex to the collapsed surface, kept per vertex the collapses
/// started from (label: input vertex -> that vertex, -1 for none). Back: each live triangle's
/// centre, corners and side middles to the input, kept per corner. On the engine's threads; the
/// same bits for any team size. With a rival, the measure stops (complete false) as soon as the
/// input's vertices show the run is not within it: their mean or one of them is beyond it.
Deviation surface_deviation(const Mesh& mesh, const InputSurface& input, const std::vector<int32_t>& label,
                          Collapser& collapser, const std::vector<int32_t>& triangles,
                          const Rival* rival = nullptr);

/// Point `index` of a triangle's grid of k steps a side ((k + 1)(k + 2) / 2 points, row by row
/// from corner a): written to p.
inline void triangle_grid_point(const double* a, const double* b, const double* c, int k, int64_t index, double* p) {
  int64_t j = index, row = 0;  // row `row` (weight of a: k - row), column j
  while (j > row) j -= ++row;
  const double w[3] = {double(k - row) / k, double(row - j) / k, double(j) / k};
  for (int d = 0; d < 3; ++d) p[d] = w[0] * a[d] + w[1] * b[d] + w[2] * c[d];
}

/// The largest squared distance to the input from points spread over the live triangles
/// around vertex v (each split k times along its sides: the corners and every grid point),
/// finer than surface_deviation's few points per triangle, for a check of one collapse.
double farthest_around(const InputSurface& input, const Collapser& collapser, const std::vector<int32_t>& triangles,
                       int32_t v, int k);

}  // namespace topstoc
