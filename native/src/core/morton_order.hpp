// Points in the order of a Z-order (Morton) curve: nearby points come one after the other, which
// the mesh's internal numbering and batches of closest-point queries (their hints) rely on.
#pragma once

#include <cstdint>
#include <vector>

namespace topstoc {

/// The ids 0..n-1 of points (3 coordinates each) along a Z-order curve of their bounding box
/// (10 bits per axis; ties keep the ids' order).
std::vector<int32_t> morton_order(const double* positions, int32_t n);

}  // namespace topstoc
