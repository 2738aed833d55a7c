#include "distance/vertex_grid.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/counting_sort.hpp"

namespace topstoc {

namespace {

constexpr int kAxisBits = 20;  // at most 2^20 cells along an axis
constexpr int64_t kMaxRings = 6;  // rings searched before every vertex is

struct CellItem {
  uint64_t code;  // the cell's key
  int32_t vertex;
};

// Items by their lowest `bits` bits of code, ties in their given order: least-significant-digit
// passes of the engine's stable counting sort.
void sort_by_code(std::vector<CellItem>& items, int bits) {
  constexpr int kDigit = 11;
  constexpr uint64_t kMask = (uint64_t(1) << kDigit) - 1;
  std::vector<CellItem> other(items.size());
  std::vector<int32_t> offsets;
  for (int shift = 0; shift < bits; shift += kDigit) {
    stable_counting_sort(
        int64_t(items.size()), int32_t(kMask + 1), [&](int64_t i) { return int32_t((items[i].code >> shift) & kMask); },
        [&](int64_t i, int32_t at) { other[size_t(at)] = items[size_t(i)]; }, offsets);
    items.swap(other);
  }
}

uint64_t mix(uint64_t key) { return key * 0x9E3779B97F4A7C15ULL; }

}  // namespace

VertexGrid::VertexGrid(const Surface& surface, double cell) : positions_(surface.positions()) {
  const auto& used = surface.used();
  double hi[3];
  for (int k = 0; k < 3; ++k) lo_[k] = std::numeric_limits<double>::infinity(), hi[k] = -lo_[k];
  for (int32_t v = 0; v < surface.num_vertices(); ++v)
    if (used[v])
      for (int k = 0; k < 3; ++k)
        lo_[k] = std::min(lo_[k], positions_[3 * size_t(v) + k]), hi[k] = std::max(hi[k], positions_[3 * size_t(v) + k]);
  const double span = std::max({hi[0] - lo_[0], hi[1] - lo_[1], hi[2] - lo_[2], 0.0});
  cell_ = std::max(cell > 0.0 && std::isfinite(cell) ? cell : span, span / double((1 << kAxisBits) - 2));
  if (!(cell_ > 0.0)) cell_ = 1.0;  // every vertex in one point
  for (int k = 0; k < 3; ++k) extent_[k] = int64_t((hi[k] - lo_[k]) / cell_) + 1;
  std::vector<CellItem> items;
  items.reserve(size_t(surface.num_vertices()));
  for (int32_t v = 0; v < surface.num_vertices(); ++v) {
    if (!used[v]) continue;
    int64_t c[3];
    for (int k = 0; k < 3; ++k)
      c[k] = std::min(extent_[k] - 1, int64_t((positions_[3 * size_t(v) + k] - lo_[k]) / cell_));
    items.push_back({key_of(c[0], c[1], c[2]), v});
  }
  sort_by_code(items, 3 * kAxisBits);
  order_.resize(items.size());
  for (size_t i = 0; i < items.size(); ++i) {
    order_[i] = items[i].vertex;
    if (i == 0 || items[i].code != items[i - 1].code) {
      cell_key_.push_back(items[i].code);
      cell_start_.push_back(int64_t(i));
    }
  }
  cell_start_.push_back(int64_t(items.size()));
  int bits = 1;
  while ((int64_t(1) << bits) < 2 * num_cells()) ++bits;
  table_shift_ = 64 - bits;
  table_.assign(size_t(1) << bits, -1);
  for (int64_t c = 0; c < num_cells(); ++c) {
    size_t slot = size_t(mix(cell_key_[size_t(c)]) >> table_shift_);
    while (table_[slot] >= 0) slot = (slot + 1) & (table_.size() - 1);
    table_[slot] = c;
  }
}

uint64_t VertexGrid::key_of(int64_t x, int64_t y, int64_t z) const {
  return uint64_t(x) | uint64_t(y) << kAxisBits | uint64_t(z) << (2 * kAxisBits);
}

int64_t VertexGrid::find(uint64_t key) const {
  for (size_t slot = size_t(mix(key) >> table_shift_);; slot = (slot + 1) & (table_.size() - 1)) {
    const int64_t c = table_[slot];
    if (c < 0 || cell_key_[size_t(c)] == key) return c;
  }
}

VertexGrid::Nearest VertexGrid::nearest(const double* p) const {
  Nearest best;
  best.distance2 = std::numeric_limits<double>::infinity();
  int64_t home[3];
  double outside2 = 0.0;  // squared distance from p to the grid's box
  for (int k = 0; k < 3; ++k) {
    const double x = (p[k] - lo_[k]) / cell_;
    home[k] = std::clamp(int64_t(std::floor(std::clamp(x, -1.0, double(extent_[k])))), int64_t(0), extent_[k] - 1);
    const double gap = std::max({0.0, lo_[k] - p[k], p[k] - (lo_[k] + cell_ * double(extent_[k]))});
    outside2 += gap * gap;
  }
  auto visit_cell = [&](int64_t c) {
    for (int64_t i = cell_start_[size_t(c)]; i < cell_start_[size_t(c) + 1]; ++i) {
      const double* q = &positions_[3 * size_t(order_[size_t(i)])];
      const double d2 = (p[0] - q[0]) * (p[0] - q[0]) + (p[1] - q[1]) * (p[1] - q[1]) + (p[2] - q[2]) * (p[2] - q[2]);
      if (d2 < best.distance2 || (d2 == best.distance2 && order_[size_t(i)] < best.vertex))
        best = {d2, order_[size_t(i)]};
    }
  };
  auto visit = [&](int64_t x, int64_t y, int64_t z) {
    if (x < 0 || y < 0 || z < 0 || x >= extent_[0] || y >= extent_[1] || z >= extent_[2]) return;
    const int64_t c = find(key_of(x, y, z));
    if (c >= 0) visit_cell(c);
  };
  // Cells of ring r lie at least (r - 1) cells from p's projection onto the grid's box (p's own
  // cell is clamped into the grid), so at least this far from p: none can hold a nearer vertex
  // once it exceeds the best. Past kMaxRings rings every vertex is looked at.
  for (int64_t r = 0;; ++r) {
    const double inside = std::max(0.0, double(r - 1)) * cell_;
    if (best.vertex >= 0 && outside2 + inside * inside > best.distance2) break;
    if (r > kMaxRings) {
      for (int64_t c = 0; c < num_cells(); ++c) visit_cell(c);
      break;
    }
    for (int64_t dx = -r; dx <= r; ++dx)
      for (int64_t dy = -r; dy <= r; ++dy) {
        const bool side = std::abs(dx) == r || std::abs(dy) == r;
        for (int64_t dz = -r; dz <= r; dz += side ? 1 : std::max<int64_t>(1, 2 * r))
          visit(home[0] + dx, home[1] + dy, home[2] + dz);
      }
  }
  return best;
}

}  // namespace topstoc
