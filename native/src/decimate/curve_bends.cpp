#include "curve_bends.hpp"

#include <algorithm>
#include <cmath>

namespace topstoc {

namespace {

// Cosine of the turn at b between the directions a -> b and b -> c (1, no turn, when either
// segment has no length).
double turn_cosine(const double* a, const double* b, const double* c) {
  double in[3], out[3], dot = 0, in2 = 0, out2 = 0;
  for (int k = 0; k < 3; ++k) {
    in[k] = b[k] - a[k], out[k] = c[k] - b[k];
    dot += in[k] * out[k], in2 += in[k] * in[k], out2 += out[k] * out[k];
  }
  return in2 > 0 && out2 > 0 ? dot / std::sqrt(in2 * out2) : 1.0;
}

double squared_distance(const double* a, const double* b) {
  return (a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) + (a[2] - b[2]) * (a[2] - b[2]);
}

struct Bend {
  double cosine;  // the larger (milder) of the turns over one and over two edges
  int32_t vertex;
  bool operator<(const Bend& o) const { return cosine < o.cosine || (cosine == o.cosine && vertex < o.vertex); }
};

// The bends of one curve (its vertices in order, closed or running from corner to corner).
// Each vertex's sharpness is computed once; a bend is compared with the two on either side.
void curve_bends(const Mesh& mesh, const int32_t* curve, int32_t n, bool closed, std::vector<Bend>& out) {
  if (n < (closed ? 5 : 3)) return;
  auto at = [&](int32_t i) {  // the i-th vertex, wrapped on a closed curve, else held at the ends
    return curve[closed ? (i % n + n) % n : std::clamp(i, 0, n - 1)];
  };
  const int32_t first = closed ? 0 : 1, last = closed ? n : n - 1;  // an open curve's ends are corners
  std::vector<Bend> sharpness(n, Bend{1.0, -1});
  for (int32_t i = first; i < last; ++i) {
    const double* p = mesh.position(at(i));
    sharpness[i] = Bend{std::max(turn_cosine(mesh.position(at(i - 1)), p, mesh.position(at(i + 1))),
                                 turn_cosine(mesh.position(at(i - 2)), p, mesh.position(at(i + 2)))),
                        at(i)};
  }
  const double limit = std::cos(kBendAngle);
  for (int32_t i = first; i < last; ++i) {
    const Bend& bend = sharpness[i];
    if (bend.cosine >= limit) continue;
    bool sharpest = true;
    for (int32_t d = -2; d <= 2 && sharpest; ++d) {
      const int32_t j = i + d;
      if (d == 0 || (!closed && (j < first || j >= last))) continue;
      sharpest = bend < sharpness[(j % n + n) % n];
    }
    if (sharpest) out.push_back(bend);
  }
}

// Mesh boundaries only (a curve vertex of one sector): forced samples on a UV seam left the
// spider of tests/data with output corners taking a UV from across the seam.
bool traced_boundary(const Mesh& mesh, const FeatureLayout& layout, int32_t begin, int32_t end) {
  return end - begin >= 3 && layout.sectors_of(mesh, layout.curve_vertices[begin + 1]) == 1;
}

}  // namespace

std::vector<int32_t> find_curve_bends(const Mesh& mesh, const FeatureLayout& layout) {
  std::vector<Bend> bends;
  for (int32_t c = 0; c < layout.num_curves(); ++c) {
    const int32_t begin = layout.curve_offsets[c], end = layout.curve_offsets[c + 1];
    if (!traced_boundary(mesh, layout, begin, end)) continue;
    curve_bends(mesh, layout.curve_vertices.data() + begin, end - begin, layout.curve_closed[c] != 0, bends);
  }
  std::sort(bends.begin(), bends.end());
  std::vector<int32_t> vertices(bends.size());
  for (size_t i = 0; i < bends.size(); ++i) vertices[i] = bends[i].vertex;
  return vertices;
}

std::vector<int32_t> find_sharp_turns(const Mesh& mesh, const FeatureLayout& layout, double edge_ratio) {
  const double limit = std::cos(kBendAngle), ratio2 = edge_ratio * edge_ratio;
  std::vector<int32_t> turns;
  for (int32_t c = 0; c < layout.num_curves(); ++c) {
    const int32_t begin = layout.curve_offsets[c], end = layout.curve_offsets[c + 1], n = end - begin;
    if (!traced_boundary(mesh, layout, begin, end)) continue;
    const int32_t* curve = layout.curve_vertices.data() + begin;
    const bool closed = layout.curve_closed[c] != 0;
    for (int32_t i = closed ? 0 : 1; i < (closed ? n : n - 1); ++i) {
      const int32_t a = curve[(i + n - 1) % n], b = curve[i], d = curve[(i + 1) % n];
      const double in2 = squared_distance(mesh.position(a), mesh.position(b));
      const double out2 = squared_distance(mesh.position(b), mesh.position(d));
      if ((in2 > ratio2 * out2 || out2 > ratio2 * in2) &&
          turn_cosine(mesh.position(a), mesh.position(b), mesh.position(d)) < limit)
        turns.push_back(b);
    }
  }
  return turns;
}

}  // namespace topstoc
