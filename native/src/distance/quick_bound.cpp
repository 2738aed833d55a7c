// A guaranteed upper bound of the symmetric Hausdorff max between a big surface A (an original)
// and a small one B (its decimation) that builds no search structure over A's triangles.
//
// A to B: A's vertices are grouped by the cells of a grid (vertex_grid.hpp); one vertex per cell
// is measured against B's BVH, the others against the triangle of B found for it (any triangle
// of B bounds the distance to B from above). A triangle of A whose corners were all measured
// against one triangle T of B lies no farther from B than its farthest corner from T (the
// distance to T is convex); otherwise no farther than its farthest corner bound plus its
// nearest-corner reach (the distance to B is 1-Lipschitz). The corners of triangles whose bound
// exceeds (1 + tolerance) times the largest distance measured are then measured exactly (each
// once), and the triangles still above it bracketed exactly (bounded_max.hpp).
// B to A: the distance from a point of B to the triangles around a vertex of A bounds its
// distance to A from above (the vertex: the grid's nearest for B's vertices, then reached by
// stepping to nearer neighbours from the one found for a neighbouring point; where that bound
// exceeds A's largest distance to B found, the grid's nearest too, then an exact search). Over
// a piece of a triangle of B it is at most the largest at its corners plus the piece's
// nearest-corner reach, or the farthest corner from a corner's triangle of A (convex); pieces
// are split at their edge midpoints until that is within (1 + tolerance) of the largest corner
// value (highest first, kMaxSplits splits at most; kRetrySplits where few triangles need more).
// Before a piece is split, A's triangles near it may settle it at once: where they lie beneath it
// like a sheet, their planes' heights over it bound it (projected_bound.hpp).
// The lower bound is attained: the largest distance measured exactly from a point of A to B, or
// from one of the kTopExact points of B with the largest bounds to A (through the grid).
#include "topstoc/distance/hausdorff.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <functional>
#include <limits>
#include <utility>
#include <vector>

#include "../core/ordered_sum.hpp"
#include "distance/bounded_max.hpp"
#include "distance/edge_cut.hpp"
#include "distance/fan_cut.hpp"
#include "distance/projected_bound.hpp"
#include "distance/vertex_grid.hpp"
#include "distance/vertex_stars.hpp"
#include "topstoc/core/parallel.hpp"

namespace topstoc {

namespace {

constexpr int64_t kCellBlock = 64;     // grid cells one task measures, chaining its BVH hints
constexpr int kMaxSplits = 256;        // splits of a triangle of B at most
// A triangle of B still open after kMaxSplits gets kRetrySplits where at most kRetryTriangles are:
// a result close to its original has a few such triangles around its largest deviation, whose
// bound would otherwise leave the whole side to the exact walk over the original.
constexpr int kRetrySplits = 4096;
constexpr size_t kRetryTriangles = 256;
constexpr double kCellSpacings = 4.0;  // grid cell side in A's mean vertex spacings (about 8 vertices a cell)
constexpr int64_t kRefineRun = 2048;
constexpr int64_t kRefineQueries = 16 * kRefineRun;  // per run: 16 a triangle (the bracket holds when they run out)
// Distances below this fraction of the diagonal count as none (coincident surfaces): the least
// settle floor, and the floor under which a midpoint's bound is not measured exactly.
constexpr double kMeasureFloor = 1e-12;
constexpr int64_t kTopQueries = 256;
constexpr int64_t kTopExact = 16;  // points of B measured exactly (the backward lower bound)
// The bound beneath (projected_bound.hpp) is tried on pieces of B over at most kBeneathMost of A's
// mean triangles (larger ones would look at too many), at most kBeneathTries times along a piece's
// splits and again only once its area is kBeneathShrink times smaller than where it last failed
// (two splits on: a piece lying along a crease of A settles once its corners are on the crease),
// over at most kBeneathCandidates triangles of A.
constexpr double kBeneathMost = 256.0;
constexpr int kBeneathTries = 3;
constexpr double kBeneathShrink = 16.0;
constexpr double kBeneathReach = 8.0;  // tried where a piece's reach exceeds this many times its room under the limit
constexpr size_t kBeneathCandidates = 1024;

struct Corners {
  double p[3][3];
};

Corners corners_of(const Surface& s, int32_t f) {
  Corners c;
  for (int j = 0; j < 3; ++j) std::copy_n(&s.positions()[3 * size_t(s.triangles()[3 * size_t(f) + j])], 3, c.p[j]);
  return c;
}

double area(const Corners& c) {
  double e1[3], e2[3];
  for (int k = 0; k < 3; ++k) e1[k] = c.p[1][k] - c.p[0][k], e2[k] = c.p[2][k] - c.p[0][k];
  const double n[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]};
  return 0.5 * std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
}

double distance2(const double* a, const double* b) {
  return (a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) + (a[2] - b[2]) * (a[2] - b[2]);
}

// A to B, per vertex of A: an upper bound of its distance to B (exact for each cell's first
// vertex) and the triangle of B it was measured against.
struct VertexBounds {
  std::vector<double> upper;
  std::vector<int32_t> against;
  double lower = 0.0;  // the largest exact distance
  double mean = 0.0;   // the mean exact distance of the cells' first vertices (one per cell: spread over A)
  int64_t queries = 0;
};

VertexBounds bound_vertices(const Surface& a, const Surface& b, const VertexGrid& grid) {
  VertexBounds out;
  out.upper.assign(size_t(a.num_vertices()), 0.0);
  out.against.assign(size_t(a.num_vertices()), -1);
  const TriangleBvh& bvh = b.bvh();
  const auto& positions = a.positions();
  const int64_t cells = grid.num_cells();
  std::vector<double> exact(static_cast<size_t>(cells));
  const int64_t blocks = (cells + kCellBlock - 1) / kCellBlock;
  parallel_for_dynamic(0, blocks, 4, parallel_if(cells >= 4 * kCellBlock), [&](int64_t block) {
    int32_t hint = -1;
    for (int64_t c = block * kCellBlock; c < std::min(cells, (block + 1) * kCellBlock); ++c) {
      const int32_t leader = grid.order()[size_t(grid.cell_start(c))];
      const ClosestHit hit = bvh.closest(&positions[3 * size_t(leader)], hint);
      hint = hit.slot;
      exact[size_t(c)] = std::sqrt(hit.distance2);
      out.upper[size_t(leader)] = exact[size_t(c)];
      out.against[size_t(leader)] = hit.triangle;
      for (int64_t i = grid.cell_start(c) + 1; i < grid.cell_start(c + 1); ++i) {
        const int32_t v = grid.order()[size_t(i)];
        out.upper[size_t(v)] = distance_to_triangle(&positions[3 * size_t(v)], b, hit.triangle);
        out.against[size_t(v)] = hit.triangle;
      }
    }
  });
  for (double d : exact) out.lower = std::max(out.lower, d);
  out.mean = cells > 0 ? ordered_sum(cells, [&](int64_t c) { return exact[size_t(c)]; }) / double(cells) : 0.0;
  out.queries = cells;
  // The vertices whose bound exceeds the largest exact distance are measured exactly too, the
  // highest first (kTopQueries at most): the max usually lies among them, and a higher lower
  // bound settles more triangles below.
  std::vector<std::pair<double, int32_t>> above;
  for (int32_t v = 0; v < a.num_vertices(); ++v)
    if (out.upper[size_t(v)] > out.lower) above.emplace_back(out.upper[size_t(v)], v);
  const size_t top = std::min(above.size(), size_t(kTopQueries));
  std::partial_sort(above.begin(), above.begin() + ptrdiff_t(top), above.end(), std::greater<>());
  int32_t hint = -1;
  for (size_t i = 0; i < top; ++i) {
    const int32_t v = above[i].second;
    const ClosestHit hit = bvh.closest(&positions[3 * size_t(v)], hint);
    hint = hit.slot;
    out.upper[size_t(v)] = std::sqrt(hit.distance2);
    out.against[size_t(v)] = hit.triangle;
    out.lower = std::max(out.lower, out.upper[size_t(v)]);
  }
  out.queries += int64_t(top);
  return out;
}

// Per triangle of A, a bound of its distance to B from its corners' (the file comment). b_stars
// (B's triangles around each vertex), when given: the fan cut too. The first pass gives none: its
// corners were measured against their cell's triangle, and the cut settled next to nothing there
// (2.7 % more instructions on the horse at 1 %).
double triangle_bound(const Surface& a, const Surface& b, const Stars* b_stars, const VertexBounds& v, int32_t f,
                      double threshold) {
  const int32_t* t = &a.triangles()[3 * size_t(f)];
  const double corner_max = std::max({v.upper[size_t(t[0])], v.upper[size_t(t[1])], v.upper[size_t(t[2])]});
  const int32_t j0 = v.against[size_t(t[0])];
  if (j0 == v.against[size_t(t[1])] && j0 == v.against[size_t(t[2])]) return corner_max;  // convex
  const Corners c = corners_of(a, f);
  double bound = corner_max + nearest_corner_reach(c.p);
  if (bound <= threshold) return bound;
  double distance[3][3];  // [k][i]: corner i to corner k's triangle of B
  for (int k = 0; k < 3; ++k) {  // each corner's triangle of B against all three corners
    const int32_t j = v.against[size_t(t[k])];
    double farthest = 0.0;
    for (int i = 0; i < 3; ++i) farthest = std::max(farthest, distance[k][i] = distance_to_triangle(c.p[i], b, j));
    bound = std::min(bound, farthest);
  }
  // across an edge of B that two corners' triangles share: each side through its own (edge_cut.hpp),
  // the corners' distances to them read from above
  auto corner2 = [&](int i, int32_t triangle) {
    const int k = triangle == v.against[size_t(t[0])] ? 0 : triangle == v.against[size_t(t[1])] ? 1 : 2;
    return distance[k][i] * distance[k][i];
  };
  for (int k = 0; k < 3 && bound > threshold; ++k) {
    const int32_t j = v.against[size_t(t[k])], l = v.against[size_t(t[(k + 1) % 3])];
    bound = std::min(bound, edge_cut_bound(c.p, b, j, l, threshold * threshold, corner2));
  }
  if (bound > threshold && b_stars != nullptr)  // over a vertex of B that all three corners' triangles hold (fan_cut.hpp)
    bound = std::min(bound, shared_fan_cut_bound(c.p, b, *b_stars, v.against[size_t(t[0])], v.against[size_t(t[1])],
                                                 v.against[size_t(t[2])], threshold));
  return bound;
}

// Measures exactly the vertices of A flagged in `measure` (cell by cell, in fixed blocks that chain
// their BVH hints: the same results on any team size), raising the lower bound. Each cell's first
// vertex is exact already (bound_vertices) and is skipped.
void measure_flagged(const Surface& a, const Surface& b, const VertexGrid& grid, const std::vector<uint8_t>& measure,
                     VertexBounds& v) {
  const TriangleBvh& bvh = b.bvh();
  const auto& positions = a.positions();
  const int64_t cells = grid.num_cells();
  const int64_t blocks = (cells + kCellBlock - 1) / kCellBlock;
  std::vector<double> block_max(size_t(blocks), 0.0);
  std::vector<int64_t> block_queries(size_t(blocks), 0);
  parallel_for_dynamic(0, blocks, 4, parallel_if(cells >= 4 * kCellBlock), [&](int64_t block) {
    int32_t hint = -1;
    for (int64_t c = block * kCellBlock; c < std::min(cells, (block + 1) * kCellBlock); ++c)
      for (int64_t i = grid.cell_start(c) + 1; i < grid.cell_start(c + 1); ++i) {
        const int32_t vertex = grid.order()[size_t(i)];
        if (!measure[size_t(vertex)]) continue;
        const ClosestHit hit = bvh.closest(&positions[3 * size_t(vertex)], hint);
        hint = hit.slot;
        v.upper[size_t(vertex)] = std::sqrt(hit.distance2);
        v.against[size_t(vertex)] = hit.triangle;
        block_max[size_t(block)] = std::max(block_max[size_t(block)], v.upper[size_t(vertex)]);
        ++block_queries[size_t(block)];
      }
  });
  for (int64_t block = 0; block < blocks; ++block) {
    v.lower = std::max(v.lower, block_max[size_t(block)]);
    v.queries += block_queries[size_t(block)];
  }
}

// The open triangles (listed) get their corners measured exactly (each once): a corner's own
// nearest triangle of B usually settles them, where bracketing them (three queries a triangle and
// more) cost several times as many queries. Keeps in `listed` those still open; returns the
// largest bound of those settled.
double settle_by_exact_corners(const Surface& a, const Surface& b, const Stars& b_stars, const VertexGrid& grid,
                               double tolerance, double floor, VertexBounds& v, std::vector<int32_t>& listed) {
  std::vector<uint8_t> measure(size_t(a.num_vertices()), 0);
  for (int32_t f : listed)
    for (int j = 0; j < 3; ++j) measure[size_t(a.triangles()[3 * size_t(f) + j])] = 1;
  measure_flagged(a, b, grid, measure, v);
  const double threshold = std::max(v.lower * (1.0 + tolerance), floor);
  std::vector<double> bound(listed.size());
  parallel_for(0, int64_t(listed.size()), kParallelMinCostly,
               [&](int64_t i) { bound[size_t(i)] = triangle_bound(a, b, &b_stars, v, listed[size_t(i)], threshold); });
  double settled = 0.0;
  size_t kept = 0;
  for (size_t i = 0; i < listed.size(); ++i)
    if (bound[i] > threshold) listed[kept++] = listed[i];
    else settled = std::max(settled, bound[i]);
  listed.resize(kept);
  return settled;
}

struct ForwardSums {
  double settled = 0.0;   // largest bound among triangles not refined
  double longest2 = 0.0;  // the longest side's square
};

// A to B (the file comment); bounds under resolution x the larger diagonal count as settled.
void bound_forward(const Surface& a, const Surface& b, const VertexGrid& grid, double tolerance, double resolution,
                   QuickBound& out, double& reach) {
  const double floor = resolution * std::max(a.diagonal(), b.diagonal());
  VertexBounds v = bound_vertices(a, b, grid);
  const Stars b_stars(b);
  const double threshold = std::max(v.lower * (1.0 + tolerance), floor);
  std::vector<uint8_t> refine(size_t(a.num_triangles()), 0);
  const ForwardSums sums = ordered_reduce<ForwardSums>(
      a.num_triangles(),
      [&](ForwardSums& s, int64_t f) {
        const double bound = triangle_bound(a, b, nullptr, v, int32_t(f), threshold);
        if (bound > threshold) refine[size_t(f)] = 1;
        else s.settled = std::max(s.settled, bound);
        const Corners c = corners_of(a, int32_t(f));
        s.longest2 = std::max({s.longest2, distance2(c.p[0], c.p[1]), distance2(c.p[1], c.p[2]), distance2(c.p[2], c.p[0])});
      },
      [](ForwardSums& total, const ForwardSums& part) {
        total.settled = std::max(total.settled, part.settled);
        total.longest2 = std::max(total.longest2, part.longest2);
      });
  std::vector<int32_t> listed;
  for (int32_t f = 0; f < a.num_triangles(); ++f)
    if (refine[size_t(f)]) listed.push_back(f);
  const double settled = std::max(sums.settled, settle_by_exact_corners(a, b, b_stars, grid, tolerance, floor, v, listed));
  out.forward_lower = v.lower;
  out.forward_upper = std::max(v.lower, settled);
  out.forward_mean = v.mean;
  reach = std::sqrt(sums.longest2 / 3.0);  // no point of a triangle is farther from its corners
  out.queries = v.queries;
  out.refined = int64_t(listed.size());
  // Bracketed in fixed runs of triangles on the engine's threads (the same bits for any team size).
  const int64_t runs = (int64_t(listed.size()) + kRefineRun - 1) / kRefineRun;
  std::vector<MaxBracket> brackets(static_cast<size_t>(runs));
  parallel_for_dynamic(0, runs, 1, parallel_if(runs > 1), [&](int64_t r) {
    const auto first = listed.begin() + r * kRefineRun;
    const std::vector<int32_t> run(first, first + std::min<int64_t>(kRefineRun, listed.end() - first));
    brackets[size_t(r)] = bound_max_over_triangles(a, run, b, v.lower, tolerance, kRefineQueries, resolution, &b_stars);
  });
  for (const MaxBracket& bracket : brackets) {
    out.forward_lower = std::max(out.forward_lower, bracket.lower);
    out.forward_upper = std::max(out.forward_upper, bracket.upper);
    out.queries += bracket.queries;
  }
}

// A piece of B in its own plane: where a vertex of A stands over it, for the candidates of the
// bound beneath.
struct PieceFrame {
  double origin[3], u[3], v[3], n[3];
  double corner[3][2], side[3][2];  // the piece's corners in (u, v), counterclockwise, and unit sides
  bool set(const Corners& c) {
    double e1[3], e2[3];
    for (int k = 0; k < 3; ++k) origin[k] = c.p[0][k], e1[k] = c.p[1][k] - c.p[0][k], e2[k] = c.p[2][k] - c.p[0][k];
    n[0] = e1[1] * e2[2] - e1[2] * e2[1], n[1] = e1[2] * e2[0] - e1[0] * e2[2], n[2] = e1[0] * e2[1] - e1[1] * e2[0];
    const double nl = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    const double l1 = std::sqrt(e1[0] * e1[0] + e1[1] * e1[1] + e1[2] * e1[2]);
    if (!(nl > 0 && l1 > 0)) return false;
    for (int k = 0; k < 3; ++k) n[k] /= nl, u[k] = e1[k] / l1;
    v[0] = n[1] * u[2] - n[2] * u[1], v[1] = n[2] * u[0] - n[0] * u[2], v[2] = n[0] * u[1] - n[1] * u[0];
    corner[0][0] = corner[0][1] = corner[1][1] = 0.0, corner[1][0] = l1;
    corner[2][0] = e2[0] * u[0] + e2[1] * u[1] + e2[2] * u[2], corner[2][1] = e2[0] * v[0] + e2[1] * v[1] + e2[2] * v[2];
    for (int j = 0; j < 3; ++j) {
      const double* a = corner[j];
      const double* b = corner[(j + 1) % 3];
      const double length = std::hypot(b[0] - a[0], b[1] - a[1]);
      if (!(length > 0)) return false;
      side[j][0] = (b[0] - a[0]) / length, side[j][1] = (b[1] - a[1]) / length;
    }
    return true;
  }
  // Whether x lies over the piece grown by `grow` and within `height` + `grow` of its plane.
  bool near(const double* x, double grow, double height) const {
    const double d[3] = {x[0] - origin[0], x[1] - origin[1], x[2] - origin[2]};
    const double dn = d[0] * n[0] + d[1] * n[1] + d[2] * n[2];
    if (!(std::abs(dn) <= height + grow)) return false;
    const double p[2] = {d[0] * u[0] + d[1] * u[1] + d[2] * u[2], d[0] * v[0] + d[1] * v[1] + d[2] * v[2]};
    for (int j = 0; j < 3; ++j)
      if (side[j][0] * (p[1] - corner[j][1]) - side[j][1] * (p[0] - corner[j][0]) < -grow) return false;
    return true;
  }
};

// A's triangles with a corner near the piece (PieceFrame::near: over it or within `grow` of it, and
// within `limit` + `grow` of its plane), each once (listed by its first corner near it), into
// `out`; false where there are more than kBeneathCandidates or a wide star. Triangles left out can only fail the
// bound beneath (projected_bound_over).
bool triangles_near(const Corners& piece, double limit, double grow, const Surface& a, const VertexGrid& grid,
                    const Stars& stars, std::vector<int32_t>& out) {
  PieceFrame frame;
  if (!frame.set(piece)) return false;
  const auto& positions = a.positions();
  const auto& triangles = a.triangles();
  auto inside = [&](int32_t v) { return frame.near(&positions[3 * size_t(v)], grow, limit); };
  double lo[3], hi[3];
  for (int k = 0; k < 3; ++k) {
    lo[k] = std::min({piece.p[0][k], piece.p[1][k], piece.p[2][k]}) - limit - grow;
    hi[k] = std::max({piece.p[0][k], piece.p[1][k], piece.p[2][k]}) + limit + grow;
  }
  out.clear();
  bool over = false;  // more candidates than kBeneathCandidates, or a wide star (a fan's centre)
  grid.for_each_in_box(lo, hi, [&](int32_t v) {
    if (over || !inside(v)) return;
    over = stars.wide(v);
    for (int64_t i = stars.begin(v); i < stars.end(v) && !over; ++i) {
      const int32_t* t = &triangles[3 * size_t(stars.triangle(i))];
      const int32_t first = inside(t[0]) ? t[0] : inside(t[1]) ? t[1] : t[2];
      if (first == v) out.push_back(stars.triangle(i));
    }
    over = over || out.size() > kBeneathCandidates;
  });
  return !over;
}

// The bound beneath a piece of B through A's triangles near it (projected_bound_over), or
// +infinity; reached: the piece's point where it is reached.
double beneath(const Corners& piece, double limit, double grow, const Surface& a, const VertexGrid& grid,
               const Stars& stars, std::vector<int32_t>& candidates, BeneathScratch& scratch, double reached[3]) {
  if (!triangles_near(piece, limit, grow, a, grid, stars, candidates)) return std::numeric_limits<double>::infinity();
  return projected_bound_over(piece.p, a, candidates, limit, scratch, reached);
}

// A piece of B across an edge of A that two of its corners' triangles share, bounded on the edge's
// two sides each through its own triangle (edge_cut.hpp), or over a vertex of A that all three
// hold, sector by sector (fan_cut.hpp); +infinity above limit.
double cut_bound(const Corners& piece, const StarBound d[3], const Surface& a, const Stars& stars, double limit) {
  auto corner2 = [&](int i, int32_t triangle) {  // a corner's distance to its own triangle is known
    const double distance = triangle == d[i].triangle ? d[i].distance : distance_to_triangle(piece.p[i], a, triangle);
    return distance * distance;
  };
  double bound = std::numeric_limits<double>::infinity();
  for (int k = 0; k < 3; ++k)
    bound = std::min(bound, edge_cut_bound(piece.p, a, d[k].triangle, d[(k + 1) % 3].triangle, limit * limit, corner2));
  if (bound > limit)
    bound = std::min(bound, shared_fan_cut_bound(piece.p, a, stars, d[0].triangle, d[1].triangle, d[2].triangle, limit));
  return bound;
}

// B to A for one triangle of B: its pieces split until each one's bound (largest corner value
// plus reach, or the farthest corner from a corner's triangle of A: the distance to one triangle
// is convex) is within the tolerance of the largest corner value found (at least `settle`; floor:
// the bound under which a midpoint is not measured exactly).
struct PieceBound {
  double upper = 0.0;
  bool capped = false;            // stopped at its most splits with a piece above the tolerance
  int64_t queries = 0;
  double worst = 0.0;             // the largest bound at a measured point or of a piece settled beneath
  double worst_point[3] = {0, 0, 0};
};

PieceBound bound_backward_triangle(const Corners& t, const StarBound corner[3], const Surface& a, const VertexGrid& grid,
                                   const Stars& stars, double reach, double floor, double settle, double tolerance,
                                   int max_splits) {
  constexpr double kNever = std::numeric_limits<double>::infinity();
  struct Piece {
    Corners c;
    StarBound d[3];
    double upper;
    double reach;        // its nearest-corner reach
    int tries;           // bounds beneath that failed on it and the pieces it was split from
    double failed_over;  // A's mean triangles under the piece where the last of them failed
  };
  // Lipschitz, then convex through each corner's triangle of A (each triangle once; its corners
  // measured until one is as far as the bound so far, which it then cannot lower).
  auto bounded = [&](Piece& piece) {
    piece.reach = nearest_corner_reach(piece.c.p);
    piece.upper = std::max({piece.d[0].distance, piece.d[1].distance, piece.d[2].distance}) + piece.reach;
    for (int j = 0; j < 3; ++j) {
      const int32_t triangle = piece.d[j].triangle;
      if ((j > 0 && triangle == piece.d[0].triangle) || (j > 1 && triangle == piece.d[1].triangle)) continue;
      double farthest = 0.0;
      for (int i = 0; i < 3 && farthest < piece.upper; ++i)
        farthest = std::max(farthest, distance_to_triangle(piece.c.p[i], a, triangle));
      piece.upper = std::min(piece.upper, farthest);
    }
  };
  auto lower_bound_first = [](const Piece& x, const Piece& y) { return x.upper < y.upper; };
  PieceBound out;
  for (int j = 0; j < 3; ++j)
    if (corner[j].distance > out.worst) out.worst = corner[j].distance, std::copy_n(t.p[j], 3, out.worst_point);
  double best = std::max({floor, settle, corner[0].distance, corner[1].distance, corner[2].distance});
  std::vector<Piece> open{{t, {corner[0], corner[1], corner[2]}, 0.0, 0.0, 0, kNever}};
  std::vector<int32_t> candidates;
  BeneathScratch scratch;
  // The bound beneath's candidates: A's triangles with a corner within `grow` of the piece (about
  // a triangle's size; any left out can only fail that bound, never make it wrong).
  const double grow = std::min(2.0 * reach, grid.cell() / kCellSpacings);
  const double mean_area = a.area() / std::max(1, a.num_triangles());
  bounded(open.front());
  double settled = 0.0;
  // The highest bound first, max_splits at most: a result nearly on the original (a tiny max
  // against long sides) would need pieces far smaller than that; the bound holds anyway.
  for (int splits = 0; !open.empty(); ++splits) {  // pieces that settle once bounded are never queued
    std::pop_heap(open.begin(), open.end(), lower_bound_first);
    const Piece piece = open.back();
    open.pop_back();
    if (piece.upper <= best * (1.0 + tolerance)) {
      settled = std::max(settled, piece.upper);
      continue;
    }
    if (splits >= max_splits) {
      settled = std::max(settled, piece.upper);  // the highest left: every other is lower
      out.capped = true;
      break;
    }
    const double limit = best * (1.0 + tolerance);
    const double cut = cut_bound(piece.c, piece.d, a, stars, limit);
    if (cut <= limit) {  // across an edge or over a vertex of A: each part through its own triangle
      settled = std::max(settled, cut);
      continue;
    }
    const double triangles_over = area(piece.c) / mean_area;
    const double gap = limit - std::max({piece.d[0].distance, piece.d[1].distance, piece.d[2].distance});
    const bool tried = piece.tries < kBeneathTries && triangles_over * kBeneathShrink <= piece.failed_over &&
                       triangles_over <= kBeneathMost && piece.reach > kBeneathReach * gap;
    if (tried) {  // over many of A's triangles: their planes may settle it at once
      double reached[3];
      const double under = beneath(piece.c, limit, grow, a, grid, stars, candidates, scratch, reached);
      if (under <= limit) {
        settled = std::max(settled, under);
        // its highest point, a bound of its distance there, is where the lower bound may look
        if (under > out.worst) out.worst = under, std::copy_n(reached, 3, out.worst_point);
        continue;
      }
    }
    double mid[3][3];
    StarBound dm[3];
    for (int j = 0; j < 3; ++j) {
      for (int k = 0; k < 3; ++k) mid[j][k] = 0.5 * (piece.c.p[j][k] + piece.c.p[(j + 1) % 3][k]);
      dm[j] = star_distance_bound(mid[j], piece.d[j].vertex, a, stars);
      if (dm[j].distance > floor) {  // the walk may have stopped short: start from the nearest vertex too
        const StarBound again = star_distance_bound(mid[j], grid.nearest(mid[j]).vertex, a, stars);
        if (again.distance < dm[j].distance) dm[j] = again;
      }
      if (dm[j].distance > floor)  // its triangles may miss a long one that is nearer: measure exactly
        dm[j] = star_exact_distance(mid[j], dm[j], reach, a, grid, stars);
      best = std::max(best, dm[j].distance);
      if (dm[j].distance > out.worst) out.worst = dm[j].distance, std::copy_n(mid[j], 3, out.worst_point);
      ++out.queries;
    }
    const double* point[6] = {piece.c.p[0], piece.c.p[1], piece.c.p[2], mid[0], mid[1], mid[2]};
    const StarBound value[6] = {piece.d[0], piece.d[1], piece.d[2], dm[0], dm[1], dm[2]};
    static const int kChildren[4][3] = {{0, 3, 5}, {3, 1, 4}, {5, 4, 2}, {3, 4, 5}};
    for (const auto& child : kChildren) {
      Piece next;
      next.tries = piece.tries + (tried ? 1 : 0);
      next.failed_over = tried ? triangles_over : piece.failed_over;
      for (int j = 0; j < 3; ++j) {
        std::copy_n(point[child[j]], 3, next.c.p[j]);
        next.d[j] = value[child[j]];
      }
      bounded(next);
      if (next.upper <= best * (1.0 + tolerance)) {
        settled = std::max(settled, next.upper);
        continue;
      }
      open.push_back(next);
      std::push_heap(open.begin(), open.end(), lower_bound_first);
    }
  }
  // A piece settled before a later midpoint raised `best` stays settled: its bound holds anyway.
  out.upper = settled;
  return out;
}

// The triangles that stopped at kMaxSplits, bounded again with kRetrySplits where there are at
// most kRetryTriangles: kept only if every one of them then settles (else the side is left to
// the exact walk anyway, and the first bounds stand), so the result does not depend on which
// retries ran before one failed. bound(f, max_splits) bounds triangle f.
template <typename BoundTriangle>
void retry_capped(std::vector<PieceBound>& per, const BoundTriangle& bound) {
  std::vector<int32_t> capped;
  for (size_t f = 0; f < per.size(); ++f)
    if (per[f].capped) capped.push_back(int32_t(f));
  if (capped.empty() || capped.size() > kRetryTriangles) return;
  std::vector<PieceBound> again(capped.size());
  std::atomic<bool> failed{false};
  parallel_for_dynamic(0, int64_t(capped.size()), 1, parallel_if(capped.size() > 1), [&](int64_t i) {
    if (failed.load(std::memory_order_relaxed)) return;
    again[size_t(i)] = bound(capped[size_t(i)], kRetrySplits);
    if (again[size_t(i)].capped) failed.store(true, std::memory_order_relaxed);
  });
  if (failed.load()) return;
  for (size_t i = 0; i < capped.size(); ++i) {
    again[i].queries += per[size_t(capped[i])].queries;
    per[size_t(capped[i])] = again[i];
  }
}

// B to A (the file comment); settle: bounds at or under it count as settled.
void bound_backward(const Surface& a, const Surface& b, const VertexGrid& grid, double tolerance, double settle,
                    double reach, QuickBound& out) {
  const Stars stars(a);
  std::vector<StarBound> vertex(size_t(b.num_vertices()), StarBound{0.0, -1, -1});
  parallel_for(0, b.num_vertices(), kParallelMinCostly, [&](int64_t y) {
    if (!b.used()[size_t(y)]) return;
    const double* p = &b.positions()[3 * size_t(y)];
    vertex[size_t(y)] = star_distance_bound(p, grid.nearest(p).vertex, a, stars);
    if (vertex[size_t(y)].distance > out.forward_lower)
      vertex[size_t(y)] = star_exact_distance(p, vertex[size_t(y)], reach, a, grid, stars);
  });
  const double floor = std::max(out.forward_lower, kMeasureFloor * std::max(a.diagonal(), b.diagonal()));
  std::vector<PieceBound> per(size_t(b.num_triangles()));
  auto bound_triangle = [&](int32_t f, int max_splits) {
    const int32_t* t = &b.triangles()[3 * size_t(f)];
    const StarBound d[3] = {vertex[size_t(t[0])], vertex[size_t(t[1])], vertex[size_t(t[2])]};
    return bound_backward_triangle(corners_of(b, f), d, a, grid, stars, reach, floor, settle, tolerance, max_splits);
  };
  parallel_for_dynamic(0, b.num_triangles(), 16, kParallelMinCostly,
                       [&](int64_t f) { per[size_t(f)] = bound_triangle(int32_t(f), kMaxSplits); });
  retry_capped(per, bound_triangle);
  out.grid_queries = b.num_vertices();
  std::vector<std::pair<double, int32_t>> worst;
  for (int32_t f = 0; f < b.num_triangles(); ++f) {
    out.backward_upper = std::max(out.backward_upper, per[size_t(f)].upper);
    out.grid_queries += per[size_t(f)].queries;
    worst.emplace_back(per[size_t(f)].worst, f);
  }
  // The points of B with the largest bounds measured exactly: attained distances from B to A.
  const size_t top = std::min(worst.size(), size_t(kTopExact));
  std::partial_sort(worst.begin(), worst.begin() + ptrdiff_t(top), worst.end(), std::greater<>());
  for (size_t i = 0; i < top; ++i) {
    const PieceBound& p = per[size_t(worst[i].second)];
    const StarBound exact = star_exact_distance(p.worst_point, StarBound{p.worst, -1, -1}, reach, a, grid, stars);
    out.backward_lower = std::max(out.backward_lower, exact.distance);
  }
}

}  // namespace

QuickBound quick_hausdorff_bound(const Surface& a, const Surface& b, double tolerance, double resolution) {
  const double spacing = std::sqrt(2.0 * a.area() / std::max(1, a.num_triangles()));
  const VertexGrid grid(a, kCellSpacings * spacing);
  const double settled_under = std::max(resolution, kMeasureFloor);  // of the larger diagonal
  QuickBound out;
  double reach = 0.0;
  bound_forward(a, b, grid, tolerance, settled_under, out, reach);
  bound_backward(a, b, grid, tolerance, settled_under * std::max(a.diagonal(), b.diagonal()), reach, out);
  return out;
}

}  // namespace topstoc
