// A bound on the distance from a flat triangle to a surface lying beneath it like a sheet.
//
// Seen along the triangle T's normal, the triangles of the other surface B that face the same way
// form a chain U. Where the boundary of U (its sides not shared with another triangle of U in the
// opposite direction) does not cross T, every point x of T lies over a triangle of U (the count
// of U's triangles over a point is constant between boundary sides), so d(x, B) is at most the
// height of that triangle's plane over x. Heights are linear over each triangle's overlap with T,
// so their largest value sits at a corner of an overlap polygon. This settles a piece of a surface
// that runs over many small triangles of the other one in a single step, where the distance's
// Lipschitz bound would split it until its pieces were smaller than the deviation.
#pragma once

#include <vector>

#include "topstoc/distance/hausdorff.hpp"

namespace topstoc {

/// Buffers one caller reuses from call to call.
struct BeneathScratch {
  std::vector<int32_t> stack, slots;
  struct Side {
    int32_t a, b, sign;  // vertex ids (lower first) and +1 or -1 for the direction
  };
  std::vector<Side> sides;
  std::vector<uint64_t> keys;  // the sides' hash table (projected_bound.cpp's paired)
  std::vector<int32_t> nets;
  std::vector<uint32_t> seen;  // projected_bound_around's: the call that last met each triangle of `to`
  uint32_t call = 0;
};

class TriangleWalk;  // distance/triangle_walk.hpp

/// An upper bound on max over triangle p of dist(x, to), or +infinity when B does not lie under
/// the whole triangle within `limit` (or more than `max_candidates` of its triangles would be
/// looked at). along_creases: a tighter test that settles more pieces lying along a crease of B
/// (a piece on one face with a side on the crease, the other face folded over it): triangles of
/// B beyond the limit are left out rather than failing the bound, a boundary of U within a
/// tiny margin of T's sides is allowed (the margin's reach added to the bound), and the distance
/// to a triangle replaces its plane's height along T's normal where that height exceeds the limit.
double projected_bound(const double p[3][3], const Surface& to, double limit, int32_t max_candidates,
                       BeneathScratch& scratch, bool along_creases = false);

/// The same bound with along_creases, its chain U grown from the given triangles of `to` (the
/// triangles at p's corners) across the sides that meet p (and around p's corners), their
/// neighbours from `walk`, instead of gathered from `to`'s tree by box: any chain bounds what it
/// covers. Falls back to projected_bound where the chain grown does not cover p.
double projected_bound_around(const double p[3][3], const Surface& to, const TriangleWalk& walk, const int32_t* start,
                              int starts, double limit, int32_t max_candidates, BeneathScratch& scratch);

/// The same bound with along_creases over the listed triangles of `to` only, for a surface without
/// a search tree: triangles left out can fail the test (a side of U left unmatched), never make the
/// bound wrong. Its margin is at least the coordinates' rounding and grows toward the tree's share
/// of p's size only while its reach stays within half the limit: a boundary of U through p's corners
/// or along its sides, as where a result lies on its original, costs next to nothing. reached: the point of p where the bound is reached (a height over one triangle of `to`,
/// or the distance to it, so the distance there is at most the bound).
double projected_bound_over(const double p[3][3], const Surface& to, const std::vector<int32_t>& triangles,
                            double limit, BeneathScratch& scratch, double reached[3]);

}  // namespace topstoc
