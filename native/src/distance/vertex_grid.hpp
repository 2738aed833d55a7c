// Nearest vertices of a surface through a uniform grid of cells hashed by their coordinates.
//
// Built in linear time (a radix sort of the vertices by cell), where a BVH over a big surface's
// triangles costs more than measuring against it: the quick Hausdorff bound (quick_bound.hpp)
// finds with it, for points of a small surface, how far the big one's nearest vertex is (an
// upper bound of the distance to the big surface), and groups the big one's vertices by cell.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "topstoc/distance/hausdorff.hpp"

namespace topstoc {

class VertexGrid {
 public:
  /// The vertices of `surface` used by a triangle, in cells of side `cell` (> 0; enlarged when
  /// the surface would span more than 2^20 cells along an axis).
  VertexGrid(const Surface& surface, double cell);

  struct Nearest {
    double distance2 = 0.0;
    int32_t vertex = -1;
  };
  /// The nearest vertex to p (exact: the search grows ring by ring until no farther cell can hold
  /// a nearer one).
  Nearest nearest(const double* p) const;

  /// f(vertex) for every vertex within `radius` of p (and maybe a few more: the cells overlapping
  /// the cube around p).
  template <class F>
  void for_each_near(const double* p, double radius, F&& f) const {
    const double lo[3] = {p[0] - radius, p[1] - radius, p[2] - radius};
    const double hi[3] = {p[0] + radius, p[1] + radius, p[2] + radius};
    for_each_in_box(lo, hi, f);
  }

  /// f(vertex) for every vertex in the box [lo, hi] (and maybe a few more: the cells it overlaps).
  template <class F>
  void for_each_in_box(const double* lo, const double* hi, F&& f) const {
    int64_t from[3], to[3];
    for (int k = 0; k < 3; ++k) {
      from[k] = std::max<int64_t>(0, int64_t(std::floor((lo[k] - lo_[k]) / cell_)));
      to[k] = std::min<int64_t>(extent_[k] - 1, int64_t(std::floor((hi[k] - lo_[k]) / cell_)));
    }
    for (int64_t x = from[0]; x <= to[0]; ++x)
      for (int64_t y = from[1]; y <= to[1]; ++y)
        for (int64_t z = from[2]; z <= to[2]; ++z) {
          const int64_t c = find(key_of(x, y, z));
          if (c < 0) continue;
          for (int64_t i = cell_start_[size_t(c)]; i < cell_start_[size_t(c) + 1]; ++i) f(order_[size_t(i)]);
        }
  }

  int64_t num_cells() const { return int64_t(cell_key_.size()); }
  /// Vertices of cell c: order()[cell_start(c) .. cell_start(c + 1)).
  int64_t cell_start(int64_t c) const { return cell_start_[size_t(c)]; }
  const std::vector<int32_t>& order() const { return order_; }
  double cell() const { return cell_; }

 private:
  uint64_t key_of(int64_t x, int64_t y, int64_t z) const;
  int64_t find(uint64_t key) const;  ///< the cell with this key, or -1
  const std::vector<double>& positions_;
  double lo_[3] = {0, 0, 0};
  double cell_ = 1.0;
  int64_t extent_[3] = {1, 1, 1};     ///< cells along each axis
  std::vector<int32_t> order_;        ///< used vertices, cell by cell
  std::vector<uint64_t> cell_key_;    ///< per non-empty cell
  std::vector<int64_t> cell_start_;   ///< per non-empty cell, and the end
  std::vector<int64_t> table_;        ///< open-addressing hash of cell keys: cell index or -1
  int table_shift_ = 0;
};

}  // namespace topstoc
