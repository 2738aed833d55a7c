#include "distance/bounded_max.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <queue>

#include "distance/edge_cut.hpp"
#include "distance/fan_cut.hpp"
#include "distance/projected_bound.hpp"
#include "distance/triangle_walk.hpp"
#include "distance/vertex_stars.hpp"

namespace topstoc {

namespace {

// Nodes of at most this many triangles are bounded through their triangles' corners (the distance
// to one triangle of the other surface is convex, so it peaks at one of them); larger ones
// through their box's corners.
constexpr int32_t kCornerBoundSlots = 16;
// A piece that the corner bounds leave open is bounded through the other surface's triangles
// beneath it (projected_bound.hpp) when it spans about this many of them at most (larger ones
// are split first: near creases the bound fails, and a failure costs its candidates), and
// when fewer lie in its box than this.
constexpr double kBeneathSpan = 64.0;
constexpr int32_t kBeneathCandidates = 256;
// ... and when they are fewer than the pieces the Lipschitz bound would split it into (a
// candidate and a split piece cost about the same, counting the bound's failures near creases;
// measured on fandisk, the elephant, mushroom and knot1 at 92-400 triangles).
constexpr double kCandidatesPerPiece = 1.0;
// A leaf's triangle spanning at most this many triangles of the other surface is first tried
// with the bound beneath it alone (its corners measured only when that does not settle it).
constexpr double kSettleSpan = 2.5;
// A piece's quarters: of its corners 0, 1, 2 and its edges' midpoints 3 = (0,1), 4 = (1,2), 5 = (2,0).
constexpr int kQuarters[4][3] = {{0, 3, 5}, {3, 1, 4}, {5, 4, 2}, {3, 4, 5}};
constexpr double kNoBound = std::numeric_limits<double>::infinity();
// Steps a vertex's walk takes at most before the tree is asked instead (a walk from a neighbour's
// triangle takes a few).
constexpr int kWalkSteps = 16;

struct Piece {
  double p[3][3];     // corners
  double d[3];        // their distances to the other surface
  int32_t near[4];    // triangles of the other surface: nearest to each corner and to the centroid
  int32_t source;     // triangle of the sampled surface this piece lies in
  int32_t hint;       // slot of the other surface's tree near the piece: where its queries start
  double upper;       // bound on the distance over the piece
};

struct ByUpper {
  bool operator()(const Piece& a, const Piece& b) const { return a.upper < b.upper; }
};

double distance2(const double* a, const double* b) {
  return (a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) + (a[2] - b[2]) * (a[2] - b[2]);
}

}  // namespace

double nearest_corner_reach(const double p[3][3]) {
  double a2 = distance2(p[1], p[2]), b2 = distance2(p[2], p[0]), c2 = distance2(p[0], p[1]);
  const double longest2 = std::max({a2, b2, c2});
  if (!(longest2 > 0)) return 0.0;
  if (2 * longest2 >= a2 + b2 + c2) return 0.5 * std::sqrt(longest2);  // right or obtuse
  // circumradius R = abc / (4 area), 16 area^2 = 2(a2 b2 + b2 c2 + c2 a2) - (a2^2 + b2^2 + c2^2);
  // in units of the longest side, so that large coordinates cannot overflow the products
  a2 /= longest2, b2 /= longest2, c2 /= longest2;
  const double area16 = 2 * (a2 * b2 + b2 * c2 + c2 * a2) - (a2 * a2 + b2 * b2 + c2 * c2);
  if (!(area16 > 0)) return 0.5 * std::sqrt(longest2);
  return std::sqrt(longest2) * std::sqrt(a2 * b2 * c2 / area16);
}

namespace {

// One bound_max_distance run: pieces of the sampled surface in a queue by their upper bound,
// the worst split into four until the bound is within the tolerance of the best distance found.
class MaxSearch {
 public:
  MaxSearch(const Surface& from, const std::vector<double>& vertex_distance, const Surface& to, double start,
            const double* start_point, double relative_tolerance, int64_t max_queries, double resolution = 1e-13,
            bool by_quarters = false)
      : from(from), vertex_distance(vertex_distance), to(to), to_positions(to.positions()), to_triangles(to.triangles()),
        bvh(to.bvh()), relative_tolerance(relative_tolerance), max_queries(max_queries),
        floor(resolution * std::max(from.diagonal(), to.diagonal())),
        to_mean_area(to.area() / std::max(1, to.num_triangles())), by_quarters(by_quarters) {
    out.lower = start;
    std::copy_n(start_point, 3, out.lower_point);
  }

  // to_stars: see fans; from_stars: the sampled surface's (the vertex-first search's walk).
  MaxBracket run(const Stars* to_stars = nullptr, const Stars* from_stars = nullptr) {
    fans = to_stars;
    own = from_stars;
    seed_pieces();
    return run_queue();
  }

  // Splits the queued pieces, worst first, until the rest is tolerated or the budget is spent.
  MaxBracket run_queue() {
    while (!open.empty()) {
      if (tolerated(open.top().upper)) break;  // the best remaining cannot beat the tolerance
      if (spent(7)) break;
      const Piece piece = open.top();
      open.pop();
      subdivide(piece);
    }
    out.converged = open.empty() || tolerated(open.top().upper);
    out.upper = std::max({out.lower, settled, open.empty() ? 0.0 : open.top().upper});
    out.tested = tested;
    return out;
  }

  // The same search over the listed triangles of the sampled surface only (the others bounded
  // by the caller).
  // to_stars: see bound_max_over_triangles.
  MaxBracket run_over(const std::vector<int32_t>& listed, const Stars* to_stars) {
    fans = to_stars;
    const auto& positions = from.positions();
    const auto& triangles = from.triangles();
    int32_t hint = -1;
    for (int32_t f : listed) {
      double corners[9];
      for (int j = 0; j < 3; ++j) std::copy_n(&positions[3 * size_t(triangles[3 * size_t(f) + j])], 3, corners + 3 * j);
      hint = add_triangle(corners, f, hint);
    }
    return run_queue();
  }

  // The same search seeded from the sampled surface's own BVH instead of all its triangles:
  // nodes by their bound, a leaf's triangles handed to the pieces when it is opened.
  MaxBracket run_from_tree(const TriangleBvh& tree, double threshold, bool lean) {
    decided_at = threshold;
    lean_ = lean && threshold >= 0.0;
    node_hint.assign(size_t(tree.num_nodes()), -1);
    open_node(tree, 0, -1);
    double top = 0.0;
    while (true) {
      const double node_top = nodes.empty() ? -1.0 : nodes.top().first;
      const double piece_top = open.empty() ? -1.0 : open.top().upper;
      top = std::max(node_top, piece_top);
      if (top < 0.0 || tolerated(top) || spent(16) ||
          (decided_at >= 0.0 && out.lower > decided_at))
        break;
      if (node_top >= piece_top) {
        const int32_t i = nodes.top().second;
        nodes.pop();
        const TriangleBvh::Node& n = tree.node(i);
        const int32_t hint = node_hint[size_t(i)];
        if (n.count > 0) {
          for (int32_t s = n.first; s < n.first + n.count; ++s)
            if (double tried_at = -1.0; !settled_beneath(tree.slot_corners(s), tried_at)) add_slot(tree, s, hint, tried_at);
        } else {
          open_node(tree, i + 1, hint);
          open_node(tree, n.first, hint);
        }
      } else {
        const Piece piece = open.top();
        open.pop();
        subdivide(piece);
      }
    }
    out.converged = top < 0.0 || tolerated(top);
    out.upper = std::max({out.lower, settled, top});
    out.tested = tested;
    return out;
  }

 private:
  const Surface& from;
  const std::vector<double>& vertex_distance;
  const Surface& to;
  const std::vector<double>& to_positions;
  const std::vector<int32_t>& to_triangles;
  const TriangleBvh& bvh;
  const double relative_tolerance;
  const int64_t max_queries;
  int64_t tested = 0;  // triangles the lookups measured and the bounds beneath looked at
  // an absolute floor (resolution x the larger diagonal; by default tiny), so that identical
  // surfaces (max 0) do not subdivide forever
  const double floor;
  const double to_mean_area;  // the mean triangle area of the other surface
  // pieces left open by their corner bounds and the bound beneath them try the bound over their
  // quarters (quarter_bound) (the vertex-first search only, whose brackets no decimation reads)
  const bool by_quarters;
  // stars of the other surface (bound_max_over_triangles', when given; bound_max_from_vertices'):
  // the pieces also try the fan cut around a vertex their corners' triangles share
  const Stars* fans = nullptr;
  const Stars* own = nullptr;  // the sampled surface's triangles around each vertex (run's from_stars)
  std::unique_ptr<const TriangleWalk> walker;  // the vertex-first search's, over the other surface
  // Whether a piece's near[j] is a triangle at distance d[j] from its corner j, its nearest but
  // where the vertex-first search's walk ended elsewhere (every search but the one seeded with the
  // caller's distances), and the cheap bounds are tried.
  bool cheap() const { return by_quarters || fans != nullptr; }
  MaxBracket out;
  BeneathScratch scratch;
  std::priority_queue<Piece, std::vector<Piece>, ByUpper> open;
  double settled = 0.0;  // the highest bound among pieces dropped as tolerated
  // run_from_tree's threshold: bounds at or below it are settled, and a distance above it ends
  // the search (whether the max exceeds it is then decided)
  double decided_at = -1.0;
  // run_from_tree's verdict-only walk (the lower bound only decides whether the max exceeds decided_at)
  bool lean_ = false;

  double threshold() const { return std::max({out.lower * (1 + relative_tolerance), floor, decided_at}); }
  // The budget: max_queries lookups, or the triangles kTestedPerQuery of them would measure on
  // average. Lookups that each measure hundreds of triangles (a flat fan's slivers, whose boxes
  // all hold its centre, tied at distance 0) would otherwise spend the budget many times over.
  bool spent(int64_t next) const {
    return out.queries + next > max_queries || tested > kTestedPerQuery * max_queries;
  }
  bool tolerated(double upper) const { return upper <= threshold(); }

  // The bound beneath a triangle (projected_bound.hpp), its candidates counted as measured.
  double beneath(const double p[3][3], bool along_creases) {
    const double bound = projected_bound(p, to, threshold(), kBeneathCandidates, scratch, along_creases);
    tested += int64_t(scratch.slots.size());
    return bound;
  }

  // The same along creases over the chain grown from a piece's corners' triangles (the
  // vertex-first search, whose walker knows the other surface's edge neighbours).
  double beneath(const Piece& piece) {
    const double bound =
        projected_bound_around(piece.p, to, *walker, piece.near, 4, threshold(), kBeneathCandidates, scratch);
    tested += int64_t(scratch.slots.size());
    return bound;
  }

  // The nearest point of the other surface to a point that need not lie on the sampled one.
  // hint: a slot found near x (the queue's order jumps about, so the previous query's is not).
  ClosestHit nearest(const double* x, int32_t hint) {
    const ClosestHit hit = bvh.closest_counted(x, hint, tested);
    ++out.queries;
    return hit;
  }

  ClosestHit query(const double* x, int32_t hint) {
    const ClosestHit hit = nearest(x, hint);
    if (std::sqrt(hit.distance2) > out.lower) {
      out.lower = std::sqrt(hit.distance2);
      std::copy_n(x, 3, out.lower_point);
      out.lower_triangle = -2;  // set by the caller of query
    }
    return hit;
  }

  // Two bounds (the distance is 1-Lipschitz; and the distance to one fixed triangle of the
  // other surface is convex, so over the piece it peaks at a corner): the smaller one holds.
  void bound(Piece& piece) const {
    double upper = std::max({piece.d[0], piece.d[1], piece.d[2]}) + nearest_corner_reach(piece.p);
    for (int n = 0; n < 4; ++n) {
      const int32_t j = piece.near[n];
      if (j < 0 || std::find(piece.near, piece.near + n, j) != piece.near + n) continue;  // tried already
      double farthest = 0.0;
      for (int i = 0; i < 3; ++i) farthest = std::max(farthest, corner_distance2(piece, i, j));
      upper = std::min(upper, std::sqrt(farthest));
    }
    piece.upper = upper;
  }

  // The squared distance from a piece's corner to a triangle of the other surface: known where
  // that is the corner's nearest (the vertex-first search), else measured.
  double corner_distance2(const Piece& piece, int corner, int32_t triangle) const {
    if (cheap() && piece.near[corner] == triangle) return piece.d[corner] * piece.d[corner];
    return distance2_to(triangle, piece.p[corner]);
  }

  double distance2_to(int32_t triangle, const double* x) const {
    const int32_t* ids = &to_triangles[3 * size_t(triangle)];
    double closest[3];
    return closest_point_on_triangle(x, &to_positions[3 * size_t(ids[0])], &to_positions[3 * size_t(ids[1])],
                                     &to_positions[3 * size_t(ids[2])], closest);
  }

  // The convex bound on each quarter of a piece (cut at its edges' midpoints) with the best of
  // the triangles nearest to its corners: where the piece straddles an edge of the other surface,
  // each side gets the triangle beneath it, not one triangle for the whole piece. +infinity when
  // a quarter stays above the threshold (the piece is split then).
  double quarter_bound(const Piece& piece) const {
    int32_t candidate[4];
    int count = 0;
    for (int32_t j : piece.near)
      if (j >= 0 && std::find(candidate, candidate + count, j) == candidate + count) candidate[count++] = j;
    if (count < 2) return kNoBound;  // bound() tried the one triangle over the whole piece
    double point[6][3], value[4][6];  // corners, then midpoints m0 = (0,1), m1 = (1,2), m2 = (2,0)
    for (int i = 0; i < 3; ++i) {
      std::copy_n(piece.p[i], 3, point[i]);
      for (int k = 0; k < 3; ++k) point[3 + i][k] = 0.5 * (piece.p[i][k] + piece.p[(i + 1) % 3][k]);
    }
    for (int n = 0; n < count; ++n)
      for (int i = 0; i < 6; ++i)
        value[n][i] = i < 3 ? corner_distance2(piece, i, candidate[n]) : distance2_to(candidate[n], point[i]);
    const double limit = threshold() * threshold();
    double worst = 0.0;
    for (const auto& quarter : kQuarters) {
      double best = kNoBound;
      for (int n = 0; n < count; ++n)
        best = std::min(best, std::max({value[n][quarter[0]], value[n][quarter[1]], value[n][quarter[2]]}));
      if (best > limit) return kNoBound;
      worst = std::max(worst, best);
    }
    return std::sqrt(worst);
  }

  // The convex bound on the piece cut through an edge that two of its corners' nearest triangles
  // share (edge_cut.hpp). +infinity where no two share an edge.
  double cut_bound(const Piece& piece) const {
    double best = kNoBound;
    const double limit = threshold() * threshold();
    auto corner2 = [&](int i, int32_t triangle) { return corner_distance2(piece, i, triangle); };
    for (int a = 0; a < 4; ++a)
      for (int b = a + 1; b < 4; ++b) {
        best = std::min(best, edge_cut_bound(piece.p, to, piece.near[a], piece.near[b], limit, corner2));
        if (tolerated(best)) return best;
      }
    return best;
  }

  void centroid_near(Piece& piece) {
    double centroid[3];
    for (int k = 0; k < 3; ++k) centroid[k] = (piece.p[0][k] + piece.p[1][k] + piece.p[2][k]) / 3.0;
    const ClosestHit hit = query(centroid, piece.hint);
    if (out.lower_triangle == -2) out.lower_triangle = piece.source;
    piece.near[3] = hit.triangle;
  }

  // Bounds a new piece (by the triangles beneath it when its corners' do not settle it, then by
  // its quarters, which settled about 1 % of the pieces they were tried on before the bound
  // beneath, then with its centroid's nearest triangle, a query that rarely settles a piece the
  // bound beneath left open) and queues it unless tolerated.
  // beneath_tried_at: the threshold at which the bound beneath this piece already failed (-1:
  // not tried); at the same threshold it would fail again.
  void keep(Piece& piece, double beneath_tried_at = -1.0) {
    bound(piece);
    if (cheap() && !tolerated(piece.upper)) settle_cheaply(piece);
    // only a bound that settles the piece is looked for: the box searched stays small
    if (!tolerated(piece.upper) && beneath_tried_at != threshold() && worth_projecting(piece))
      piece.upper = std::min(piece.upper, by_quarters ? beneath(piece) : beneath(piece.p, false));
    if (cheap() && !tolerated(piece.upper)) piece.upper = std::min(piece.upper, quarter_bound(piece));
    if (!tolerated(piece.upper)) {
      centroid_near(piece);
      bound(piece);
    }
    if (tolerated(piece.upper)) {
      settled = std::max(settled, piece.upper);
    } else {
      open.push(piece);
    }
  }

  // The vertex-first search's bounds that cost a few distances, before the bound beneath: the
  // piece cut along an edge of the other surface, then around a vertex.
  void settle_cheaply(Piece& piece) {
    piece.upper = std::min(piece.upper, cut_bound(piece));
    if (!tolerated(piece.upper) && fans != nullptr)
      piece.upper = std::min(piece.upper, shared_fan_cut_bound(piece.p, to, *fans, piece.near[0], piece.near[1],
                                                               piece.near[2], threshold()));
  }

  // About how many triangles of the other surface a triangle spans (one more than its area over
  // their mean area).
  double spanned(const double p[3][3]) const {
    double u[3], w[3], n[3];
    for (int k = 0; k < 3; ++k) u[k] = p[1][k] - p[0][k], w[k] = p[2][k] - p[0][k];
    n[0] = u[1] * w[2] - u[2] * w[1], n[1] = u[2] * w[0] - u[0] * w[2], n[2] = u[0] * w[1] - u[1] * w[0];
    return 1.0 + 0.5 * std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]) / to_mean_area;
  }

  // Whether the bound through the triangles beneath a piece costs less than the splits the
  // Lipschitz bound needs to settle it: about (reach / slack)^2 pieces, against about two
  // candidates per triangle of the other surface the piece spans.
  bool worth_projecting(const Piece& piece) const {
    const double candidates = 2.0 * spanned(piece.p) - 1.0;
    if (candidates > kBeneathSpan) return false;
    const double slack = threshold() - std::max({piece.d[0], piece.d[1], piece.d[2]});
    if (!(slack > 0)) return true;
    const double splits = nearest_corner_reach(piece.p) / slack;
    return candidates < kCandidatesPerPiece * splits * splits;
  }

  // A leaf's triangle settled by the bound beneath it without measuring its corners, where the
  // other surface is far coarser (a tiny result seen from its input): a few candidates.
  // tried_at: the threshold at which the bound was tried and failed (else left as it was).
  bool settled_beneath(const double* corners, double& tried_at) {
    const double p[3][3] = {{corners[0], corners[1], corners[2]}, {corners[3], corners[4], corners[5]},
                            {corners[6], corners[7], corners[8]}};
    if (spanned(p) > kSettleSpan) return false;
    const double bound = beneath(p, false);
    if (!tolerated(bound)) {
      tried_at = threshold();
      return false;
    }
    settled = std::max(settled, bound);
    return true;
  }

  // run_from_tree's open nodes: (bound, node) in the queue's order, and the slot of the other
  // surface's tree nearest to the node's centre (its children's queries start there)
  std::priority_queue<std::pair<double, int32_t>> nodes;
  std::vector<int32_t> node_hint;

  // Bounds every point in a node's box: its centre's distance plus half the box diagonal
  // (1-Lipschitz), or the farthest corner (of its triangles, or of the box) from the centre's
  // nearest triangle (convex). A point of the surface in the node (its first triangle's
  // centroid) raises the lower bound.
  void open_node(const TriangleBvh& tree, int32_t i, int32_t hint) {
    const TriangleBvh::Node& n = tree.node(i);
    double centre[3], half2 = 0.0;
    for (int k = 0; k < 3; ++k) {
      centre[k] = 0.5 * (n.lo[k] + n.hi[k]);
      half2 += 0.25 * (n.hi[k] - n.lo[k]) * (n.hi[k] - n.lo[k]);
    }
    const ClosestHit hit = nearest(centre, hint);
    node_hint[size_t(i)] = hit.slot;
    double upper = std::sqrt(hit.distance2) + std::sqrt(half2);
    const double* a = &to_positions[3 * size_t(to_triangles[3 * size_t(hit.triangle)])];
    const double* b = &to_positions[3 * size_t(to_triangles[3 * size_t(hit.triangle) + 1])];
    const double* c = &to_positions[3 * size_t(to_triangles[3 * size_t(hit.triangle) + 2])];
    // A node's triangles fill slots [first, last): from its leftmost leaf to its rightmost one.
    int32_t leaf = i, right = i;
    while (tree.node(leaf).count == 0) ++leaf;
    while (tree.node(right).count == 0) right = tree.node(right).first;
    const int32_t first = tree.node(leaf).first, last = tree.node(right).first + tree.node(right).count;
    double farthest = 0.0, closest[3];
    if (last - first <= kCornerBoundSlots) {  // the triangles' own corners: tight where the surfaces are close
      for (int32_t s = first; s < last; ++s)
        for (int j = 0; j < 3; ++j)
          farthest = std::max(farthest, closest_point_on_triangle(tree.slot_corners(s) + 3 * j, a, b, c, closest));
    } else {
      for (int corner = 0; corner < 8; ++corner) {
        const double x[3] = {corner & 1 ? n.hi[0] : n.lo[0], corner & 2 ? n.hi[1] : n.lo[1],
                             corner & 4 ? n.hi[2] : n.lo[2]};
        farthest = std::max(farthest, closest_point_on_triangle(x, a, b, c, closest));
      }
    }
    upper = std::min(upper, std::sqrt(farthest));
    // lean: a node its bound settles needs no lower bound from it.
    if (!lean_ || !tolerated(upper)) {
      const double* t = tree.slot_corners(first);
      const double centroid[3] = {(t[0] + t[3] + t[6]) / 3.0, (t[1] + t[4] + t[7]) / 3.0, (t[2] + t[5] + t[8]) / 3.0};
      query(centroid, hit.slot);
      if (out.lower_triangle == -2) out.lower_triangle = tree.slot_triangle(first);
    }
    if (tolerated(upper)) {
      settled = std::max(settled, upper);
    } else {
      nodes.emplace(upper, i);
    }
  }

  // One triangle of the sampled surface as a piece: its corners measured, then bounded.
  // Returns the slot found nearest to its last corner (where a neighbour's queries start).
  int32_t add_triangle(const double* corners, int32_t source, int32_t hint) {
    Piece piece;
    piece.source = source;
    for (int j = 0; j < 3; ++j) {
      std::copy_n(corners + 3 * j, 3, piece.p[j]);
      const ClosestHit hit = query(piece.p[j], hint);
      hint = hit.slot;
      if (out.lower_triangle == -2) out.lower_triangle = source;
      piece.d[j] = std::sqrt(hit.distance2);
      piece.near[j] = hit.triangle;
    }
    piece.near[3] = -1;
    piece.hint = hint;
    keep(piece);
    return hint;
  }

  // run_from_tree's measured corners, per vertex of the sampled surface (allocated at the first
  // leaf opened): distance (-1 while unmeasured), nearest triangle and slot
  std::vector<double> vertex_d;
  std::vector<int32_t> vertex_triangle, vertex_slot_near;

  // A leaf's triangle as a piece, as add_triangle, but each vertex of the sampled surface is
  // measured once (a vertex is a corner of about six triangles): the same distances, fewer queries.
  // beneath_tried_at: as keep's.
  void add_slot(const TriangleBvh& tree, int32_t s, int32_t hint, double beneath_tried_at) {
    if (vertex_d.empty()) {
      vertex_d.assign(size_t(from.num_vertices()), -1.0);
      vertex_triangle.assign(size_t(from.num_vertices()), -1);
      vertex_slot_near.assign(size_t(from.num_vertices()), -1);
    }
    const double* corners = tree.slot_corners(s);
    Piece piece;
    piece.source = tree.slot_triangle(s);
    for (int j = 0; j < 3; ++j) {
      const size_t v = size_t(from.triangles()[3 * size_t(piece.source) + j]);
      std::copy_n(corners + 3 * j, 3, piece.p[j]);
      if (vertex_d[v] < 0.0) {
        const ClosestHit hit = query(piece.p[j], hint);
        if (out.lower_triangle == -2) out.lower_triangle = piece.source;
        vertex_d[v] = std::sqrt(hit.distance2), vertex_triangle[v] = hit.triangle, vertex_slot_near[v] = hit.slot;
      }
      hint = vertex_slot_near[v];
      piece.d[j] = vertex_d[v];
      piece.near[j] = vertex_triangle[v];
    }
    piece.near[3] = -1;
    piece.hint = hint;
    keep(piece, beneath_tried_at);
  }

  // The sampled surface's triangles as the first pieces, with each used vertex's nearest triangle.
  void seed_pieces() {
    const auto& positions = from.positions();
    const auto& triangles = from.triangles();
    std::vector<int32_t> vertex_near(from.num_vertices(), -1), vertex_slot(from.num_vertices(), -1);
    // without distances from the caller, the queries' own (the same values)
    std::vector<double> measured(vertex_distance.empty() ? from.num_vertices() : 0, 0.0);
    if (by_quarters) {
      walk_vertices(measured, vertex_near, vertex_slot);
    } else {
      int32_t hint = -1;
      for (int32_t v = 0; v < from.num_vertices(); ++v)
        if (from.used()[v]) {
          const ClosestHit hit = query(&positions[3 * size_t(v)], hint);
          vertex_near[v] = hit.triangle;
          vertex_slot[v] = hint = hit.slot;
          if (!measured.empty()) measured[v] = std::sqrt(hit.distance2);
        }
    }
    const std::vector<double>& distance = measured.empty() ? vertex_distance : measured;
    out.lower_triangle = -1;
    for (int32_t f = 0; f < from.num_triangles(); ++f) {
      Piece piece;
      piece.source = f;
      for (int j = 0; j < 3; ++j) {
        const int32_t v = triangles[3 * size_t(f) + j];
        std::copy_n(&positions[3 * size_t(v)], 3, piece.p[j]);
        piece.d[j] = distance[v];
        piece.near[j] = vertex_near[v];
      }
      piece.near[3] = -1;
      piece.hint = vertex_slot[triangles[3 * size_t(f)]];
      keep(piece);
    }
  }

  // The vertex-first search's vertices, each bounded by its distance to the triangle of the other
  // surface that a walk from a neighbour's reaches (triangle_walk.hpp; a tree lookup for the first
  // vertex of each connected part, or where the walk runs long), in walk_order. Then those whose
  // bound exceeds the largest distance looked up are looked up, the highest first, until none is
  // left: the lower bound is the vertices' largest distance, as if each had been looked up (bounds
  // within `close` aside), and the others keep bounds that are their distances where the walk
  // ended at the nearest triangle.
  void walk_vertices(std::vector<double>& distance, std::vector<int32_t>& near, std::vector<int32_t>& slot) {
    walker = std::make_unique<const TriangleWalk>(to, *fans);
    std::vector<int32_t> slot_of(size_t(to.num_triangles()));
    for (int32_t s = 0; s < to.num_triangles(); ++s) slot_of[size_t(bvh.slot_triangle(s))] = s;
    const auto& positions = from.positions();
    std::vector<char> looked_up(size_t(from.num_vertices()), 0);
    auto look_up = [&](int32_t v, int32_t hint) {
      const ClosestHit hit = query(&positions[3 * size_t(v)], hint);
      distance[v] = std::sqrt(hit.distance2), near[v] = hit.triangle, slot[v] = hit.slot, looked_up[v] = 1;
    };
    // a bound within the floor, less the tolerance, cannot raise the threshold: the walk need not
    // look for a nearer triangle, nor the vertex be looked up
    const double close = floor / (1 + relative_tolerance);
    for (const int32_t f : walk_order(from, *own)) {
      const int32_t* t = &from.triangles()[3 * size_t(f)];
      int32_t start = near[t[0]] >= 0 ? near[t[0]] : near[t[1]] >= 0 ? near[t[1]] : near[t[2]];
      for (int j = 0; j < 3; ++j) {
        const int32_t v = t[j];
        if (near[v] >= 0) continue;
        const TriangleWalk::End end = start >= 0 ? walker->walk(&positions[3 * size_t(v)], start, kWalkSteps, close)
                                                 : TriangleWalk::End{0.0, -1, false};
        if (end.settled) {
          distance[v] = std::sqrt(end.distance2), near[v] = end.triangle, slot[v] = slot_of[size_t(end.triangle)];
        } else {
          look_up(v, start >= 0 ? slot_of[size_t(start)] : -1);
        }
        start = near[v];
      }
    }
    // the vertices left whose bound is above both, as a heap: the highest bound (the lowest id
    // among equals) on top
    auto lower_first = [&](int32_t a, int32_t b) { return distance[a] != distance[b] ? distance[a] < distance[b] : a > b; };
    std::vector<int32_t> above;
    for (int32_t v = 0; v < from.num_vertices(); ++v)
      if (near[v] >= 0 && !looked_up[v] && distance[v] > std::max(out.lower, close)) above.push_back(v);
    std::make_heap(above.begin(), above.end(), lower_first);
    while (!above.empty() && distance[above.front()] > std::max(out.lower, close)) {
      const int32_t v = above.front();
      std::pop_heap(above.begin(), above.end(), lower_first);
      above.pop_back();
      look_up(v, slot[v]);
    }
  }

  // Splits a piece at its edges' midpoints into four.
  void subdivide(const Piece& piece) {
    double mid[3][3], dm[3];
    int32_t nm[3];
    for (int j = 0; j < 3; ++j) {
      const double* a = piece.p[j];
      const double* b = piece.p[(j + 1) % 3];
      for (int k = 0; k < 3; ++k) mid[j][k] = 0.5 * (a[k] + b[k]);
      const ClosestHit hit = query(mid[j], piece.hint);
      if (out.lower_triangle == -2) out.lower_triangle = piece.source;
      dm[j] = std::sqrt(hit.distance2);
      nm[j] = hit.triangle;
    }
    // Corners: 0, 1, 2; midpoints: m0 = (0,1), m1 = (1,2), m2 = (2,0).
    const double* corner[6] = {piece.p[0], piece.p[1], piece.p[2], mid[0], mid[1], mid[2]};
    const double value[6] = {piece.d[0], piece.d[1], piece.d[2], dm[0], dm[1], dm[2]};
    const int32_t near[6] = {piece.near[0], piece.near[1], piece.near[2], nm[0], nm[1], nm[2]};
    for (const auto& child : kQuarters) {
      Piece c;
      c.source = piece.source;
      for (int j = 0; j < 3; ++j) {
        std::copy_n(corner[child[j]], 3, c.p[j]);
        c.d[j] = value[child[j]];
        c.near[j] = near[child[j]];
      }
      c.near[3] = piece.near[3];
      c.hint = piece.hint;
      keep(c);
    }
  }
};

}  // namespace

MaxBracket bound_max_distance(const Surface& from, const std::vector<double>& vertex_distance, const Surface& to,
                              double start, const double* start_point, double relative_tolerance,
                              int64_t max_queries) {
  return MaxSearch(from, vertex_distance, to, start, start_point, relative_tolerance, max_queries).run();
}

MaxBracket bound_max_from_vertices(const Surface& from, const Surface& to, double relative_tolerance,
                                   double resolution, int64_t max_queries, const Stars& from_stars,
                                   const Stars& to_stars) {
  static const std::vector<double> no_vertex_distance;  // the vertices' own queries give them
  const double origin[3] = {0.0, 0.0, 0.0};
  return MaxSearch(from, no_vertex_distance, to, 0.0, origin, relative_tolerance, max_queries, resolution, true)
      .run(&to_stars, &from_stars);
}

MaxBracket bound_max_over_triangles(const Surface& from, const std::vector<int32_t>& triangles, const Surface& to,
                                    double start, double relative_tolerance, int64_t max_queries, double resolution,
                                    const Stars* to_stars) {
  static const std::vector<double> no_vertex_distance;
  const double origin[3] = {0.0, 0.0, 0.0};
  return MaxSearch(from, no_vertex_distance, to, start, origin, relative_tolerance, max_queries, resolution)
      .run_over(triangles, to_stars);
}

MaxBracket bound_max_distance_by_tree(const Surface& from, const Surface& to, double relative_tolerance,
                                      int64_t max_queries, double threshold, bool lean) {
  static const std::vector<double> no_vertex_distance;
  const double origin[3] = {0.0, 0.0, 0.0};
  MaxSearch search(from, no_vertex_distance, to, 0.0, origin, relative_tolerance, max_queries);
  return search.run_from_tree(from.bvh(), threshold, lean);
}

}  // namespace topstoc
