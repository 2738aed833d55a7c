// A bound on the distance from a triangle P to a surface S where P lies over a vertex of S.
//
// Around a vertex v whose triangles form a closed fan, the planes through v that hold the fan's mean
// normal and one of its spokes cut space into sectors, one a triangle of the fan; where each
// triangle, seen along that normal, turns the way of the fan by less than half a turn, the sectors
// chain around v and cover space. On each sector's part of P the distance to S is at most the
// distance to that sector's triangle, convex, so it peaks at a corner of the part (P clipped to
// the sector). This settles a piece lying on S across a vertex
// where its corners' nearest triangles differ and share no edge, which the edge cut (edge_cut.hpp)
// leaves open and splitting settles only once the pieces are as small as the distance.
#pragma once

#include <cstdint>

#include "distance/vertex_stars.hpp"
#include "topstoc/distance/hausdorff.hpp"

namespace topstoc {

/// The fan cut bound of triangle p around vertex v of `to`, or +infinity where v's triangles are
/// not a closed fan each turned the way of their mean normal (or are more than Stars::kWideStar),
/// or a distance exceeds limit.
double fan_cut_bound(const double p[3][3], const Surface& to, const Stars& stars, int32_t v, double limit);

/// The least fan cut bound around the vertices that triangles j, k and l of `to` all hold
/// (+infinity where they share none; a negative id shares none).
double shared_fan_cut_bound(const double p[3][3], const Surface& to, const Stars& stars, int32_t j, int32_t k,
                            int32_t l, double limit);

}  // namespace topstoc
