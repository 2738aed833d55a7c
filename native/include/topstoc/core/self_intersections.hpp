// Triangles of a surface that intersect each other, decided with exact orientation tests
// (Shewchuk's adaptive orient3d, as shipped with TetGen).
//
// Two triangles intersect when they share more than their common vertices or edge: crossing
// or touching triangles, a triangle folded onto its neighbour across their edge, two fans
// overlapping at a shared vertex. Zero-area triangles are reported too (paired with
// themselves): TetGen cannot keep them either. A triangle that names one vertex twice (a
// segment or a point) is reported that way only and not tested against the others: the pair
// tests assume three distinct corners. A uniform grid finds the candidate pairs.
#pragma once

#include <cstdint>
#include <utility>
#include <vector>

namespace topstoc {

/// Intersecting triangle pairs (i < j, sorted; (i, i) for a zero-area triangle i); at most
/// max_pairs of them (the first in that order) when max_pairs > 0. With only_with (one flag per
/// triangle), only the pairs with a flagged triangle (and flagged zero-area triangles): the
/// same pairs as filtering the full answer, at the cost of the flagged triangles' cells.
std::vector<std::pair<int32_t, int32_t>> self_intersections(const double* positions, int32_t num_vertices,
                                                            const int32_t* triangles, int32_t num_triangles,
                                                            int64_t max_pairs = 0, const uint8_t* only_with = nullptr);

/// True when triangles (a, b, c) and (p, q, r) (vertex ids into positions) intersect other than in
/// shared vertices or a shared edge. Each triangle must name three distinct vertices (throws
/// std::invalid_argument otherwise).
bool triangles_intersect(const double* positions, const int32_t* t1, const int32_t* t2);

}  // namespace topstoc
