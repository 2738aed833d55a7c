#include "distance/bounded_max.hpp"

#include <algorithm>
#include <cmath>
#include <queue>

namespace topstoc {

namespace {

struct Piece {
  double p[3][3];     // corners
  double d[3];        // their distances to the other surface
  int32_t near[4];    // triangles of the other surface: nearest to each corner and to the centroid
  int32_t source;     // triangle of the sampled surface this piece lies in
  double upper;       // bound on the distance over the piece
};

struct ByUpper {
  bool operator()(const Piece& a, const Piece& b) const { return a.upper < b.upper; }
};

double distance2(const double* a, const double* b) {
  return (a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) + (a[2] - b[2]) * (a[2] - b[2]);
}

// Largest distance from a point of the triangle to its nearest corner (see the header).
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

// One bound_max_distance run: pieces of the sampled surface in a queue by their upper bound,
// the worst split into four until the bound is within the tolerance of the best distance found.
class MaxSearch {
 public:
  MaxSearch(const Surface& from, const std::vector<double>& vertex_distance, const Surface& to, double start,
            const double* start_point, double relative_tolerance, int64_t max_queries)
      : from(from), vertex_distance(vertex_distance), to_positions(to.positions()), to_triangles(to.triangles()),
        bvh(to.bvh()), relative_tolerance(relative_tolerance), max_queries(max_queries),
        floor(1e-13 * std::max(from.diagonal(), to.diagonal())) {
    out.lower = start;
    std::copy_n(start_point, 3, out.lower_point);
  }

  MaxBracket run() {
    seed_pieces();
    while (!open.empty()) {
      if (tolerated(open.top().upper)) break;  // the best remaining cannot beat the tolerance
      if (out.queries + 7 > max_queries) break;
      const Piece piece = open.top();
      open.pop();
      subdivide(piece);
    }
    out.converged = open.empty() || tolerated(open.top().upper);
    out.upper = std::max({out.lower, settled, open.empty() ? 0.0 : open.top().upper});
    return out;
  }

 private:
  const Surface& from;
  const std::vector<double>& vertex_distance;
  const std::vector<double>& to_positions;
  const std::vector<int32_t>& to_triangles;
  const TriangleBvh& bvh;
  const double relative_tolerance;
  const int64_t max_queries;
  const double floor;  // a tiny absolute floor, so that identical surfaces (max 0) do not subdivide forever
  MaxBracket out;
  int32_t hint = -1;
  std::priority_queue<Piece, std::vector<Piece>, ByUpper> open;
  double settled = 0.0;  // the highest bound among pieces dropped as tolerated

  bool tolerated(double upper) const { return upper <= std::max(out.lower * (1 + relative_tolerance), floor); }

  ClosestHit query(const double* x) {
    const ClosestHit hit = bvh.closest(x, hint);
    hint = hit.slot;
    ++out.queries;
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
    for (int32_t j : piece.near) {
      if (j < 0) continue;
      const double* a = &to_positions[3 * size_t(to_triangles[3 * size_t(j)])];
      const double* b = &to_positions[3 * size_t(to_triangles[3 * size_t(j) + 1])];
      const double* c = &to_positions[3 * size_t(to_triangles[3 * size_t(j) + 2])];
      double farthest = 0.0, closest[3];
      for (int i = 0; i < 3; ++i) farthest = std::max(farthest, closest_point_on_triangle(piece.p[i], a, b, c, closest));
      upper = std::min(upper, std::sqrt(farthest));
    }
    piece.upper = upper;
  }

  void centroid_near(Piece& piece) {
    double centroid[3];
    for (int k = 0; k < 3; ++k) centroid[k] = (piece.p[0][k] + piece.p[1][k] + piece.p[2][k]) / 3.0;
    const ClosestHit hit = query(centroid);
    if (out.lower_triangle == -2) out.lower_triangle = piece.source;
    piece.near[3] = hit.triangle;
  }

  // Bounds a new piece (with its centroid's nearest triangle when the corners' do not settle
  // it) and queues it unless tolerated.
  void keep(Piece& piece) {
    bound(piece);
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

  // The sampled surface's triangles as the first pieces, with each used vertex's nearest triangle.
  void seed_pieces() {
    const auto& positions = from.positions();
    const auto& triangles = from.triangles();
    std::vector<int32_t> vertex_near(from.num_vertices(), -1);
    for (int32_t v = 0; v < from.num_vertices(); ++v)
      if (from.used()[v]) vertex_near[v] = query(&positions[3 * size_t(v)]).triangle;
    out.lower_triangle = -1;
    for (int32_t f = 0; f < from.num_triangles(); ++f) {
      Piece piece;
      piece.source = f;
      for (int j = 0; j < 3; ++j) {
        const int32_t v = triangles[3 * size_t(f) + j];
        std::copy_n(&positions[3 * size_t(v)], 3, piece.p[j]);
        piece.d[j] = vertex_distance[v];
        piece.near[j] = vertex_near[v];
      }
      piece.near[3] = -1;
      keep(piece);
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
      const ClosestHit hit = query(mid[j]);
      if (out.lower_triangle == -2) out.lower_triangle = piece.source;
      dm[j] = std::sqrt(hit.distance2);
      nm[j] = hit.triangle;
    }
    // Corners: 0, 1, 2; midpoints: m0 = (0,1), m1 = (1,2), m2 = (2,0).
    const double* corner[6] = {piece.p[0], piece.p[1], piece.p[2], mid[0], mid[1], mid[2]};
    const double value[6] = {piece.d[0], piece.d[1], piece.d[2], dm[0], dm[1], dm[2]};
    const int32_t near[6] = {piece.near[0], piece.near[1], piece.near[2], nm[0], nm[1], nm[2]};
    static const int kChildren[4][3] = {{0, 3, 5}, {3, 1, 4}, {5, 4, 2}, {3, 4, 5}};
    for (const auto& child : kChildren) {
      Piece c;
      c.source = piece.source;
      for (int j = 0; j < 3; ++j) {
        std::copy_n(corner[child[j]], 3, c.p[j]);
        c.d[j] = value[child[j]];
        c.near[j] = near[child[j]];
      }
      c.near[3] = piece.near[3];
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

}  // namespace topstoc
