#include "topstoc/decimate/moved_sources.hpp"

#include <cmath>
#include <limits>
#include <stdexcept>

namespace topstoc {

namespace {

// Barycentric weights of p's projection onto triangle (a, b, c), negative weights clamped to 0
// and the rest renormalised, and the distance from p to the weighted point; a degenerate
// triangle gives its first corner. The operations and their order are numpy's in
// attributes._clamped_barycentric (sums of three left to right), so both give the same bits.
double clamped_barycentric(const double* p, const double* a, const double* b, const double* c, double* w) {
  double e0[3], e1[3], d[3];
  for (int i = 0; i < 3; ++i) e0[i] = b[i] - a[i], e1[i] = c[i] - a[i], d[i] = p[i] - a[i];
  auto dot = [](const double* x, const double* y) { return (x[0] * y[0] + x[1] * y[1]) + x[2] * y[2]; };
  const double d00 = dot(e0, e0), d01 = dot(e0, e1), d11 = dot(e1, e1), d20 = dot(d, e0), d21 = dot(d, e1);
  const double denominator = d00 * d11 - d01 * d01;
  const bool ok = denominator > 0;
  const double safe = ok ? denominator : 1.0;
  const double w1 = ok ? (d11 * d20 - d01 * d21) / safe : 0.0;
  const double w2 = ok ? (d00 * d21 - d01 * d20) / safe : 0.0;
  double x[3] = {1.0 - w1 - w2, w1, w2};
  for (double& v : x) v = std::isnan(v) || v > 0.0 ? v : 0.0;  // np.clip(w, 0, None): -0 becomes +0
  const double total = (x[0] + x[1]) + x[2];
  if (total > 0) {
    for (int i = 0; i < 3; ++i) w[i] = x[i] / total;
  } else {
    w[0] = 1.0, w[1] = 0.0, w[2] = 0.0;
  }
  double r[3];
  for (int i = 0; i < 3; ++i) r[i] = p[i] - ((w[0] * a[i] + w[1] * b[i]) + w[2] * c[i]);
  return std::sqrt((r[0] * r[0] + r[1] * r[1]) + r[2] * r[2]);
}

MovedSources unmoved(int64_t num_output) {
  MovedSources out;
  out.face.assign(num_output, -1);
  out.weights.assign(3 * size_t(num_output), 0.0);
  for (int64_t v = 0; v < num_output; ++v) out.weights[3 * size_t(v)] = 1.0;
  return out;
}

// Triangle f (corners a, b, c in the clusters l) offered to each moved cluster among its corners,
// once. A vertex's source changes when strictly closer, or as close from a lower triangle id:
// the lowest triangle wins ties whatever the order the triangles come in.
void offer(int64_t f, const int32_t* l, const double* a, const double* b, const double* c, const double* output,
           const uint8_t* moved, std::vector<double>& closest, MovedSources& out) {
  for (int j = 0; j < 3; ++j) {
    const int32_t v = l[j];
    if (v < 0 || !moved[v] || (j >= 1 && v == l[0]) || (j == 2 && v == l[1])) continue;
    double w[3];
    const double distance = clamped_barycentric(output + 3 * size_t(v), a, b, c, w);
    if (!(distance < closest[v]) && !(distance == closest[v] && out.face[v] >= 0 && f < out.face[v])) continue;
    closest[v] = distance;
    out.face[v] = f;
    for (int i = 0; i < 3; ++i) out.weights[3 * size_t(v) + i] = w[i];
  }
}

}  // namespace

MovedSources moved_sources(const double* input, const int32_t* triangles, int64_t num_triangles,
                           const int32_t* labels, const double* output, const uint8_t* moved, int64_t num_output) {
  MovedSources out = unmoved(num_output);
  std::vector<double> closest(num_output, std::numeric_limits<double>::infinity());
  for (int64_t f = 0; f < num_triangles; ++f) {
    const int32_t* t = triangles + 3 * f;
    const int32_t l[3] = {labels[t[0]], labels[t[1]], labels[t[2]]};
    offer(f, l, input + 3 * size_t(t[0]), input + 3 * size_t(t[1]), input + 3 * size_t(t[2]), output, moved, closest,
          out);
  }
  return out;
}

MovedSources moved_sources(const Mesh& mesh, const int32_t* labels, const int32_t* kept, const double* output,
                           int64_t num_output) {
  if (!mesh.report().dropped_triangles.empty())
    throw std::invalid_argument("moved sources from a prepared mesh that dropped triangles: give the arrays");
  const auto& source = mesh.vertex_source();
  const std::vector<int32_t> internal = mesh.internal_ids(std::vector<int32_t>(kept, kept + num_output));
  std::vector<uint8_t> moved(num_output, 0);
  for (int64_t v = 0; v < num_output; ++v)
    for (int i = 0; i < 3; ++i) moved[v] |= output[3 * size_t(v) + i] != mesh.position(internal[v])[i];
  MovedSources out = unmoved(num_output);
  std::vector<double> closest(num_output, std::numeric_limits<double>::infinity());
  for (int32_t f = 0; f < mesh.num_faces(); ++f) {
    const int32_t* t = &mesh.faces()[3 * size_t(f)];
    const int32_t l[3] = {labels[source[t[0]]], labels[source[t[1]]], labels[source[t[2]]]};
    offer(mesh.face_source()[f], l, mesh.position(t[0]), mesh.position(t[1]), mesh.position(t[2]), output,
          moved.data(), closest, out);
  }
  return out;
}

}  // namespace topstoc
