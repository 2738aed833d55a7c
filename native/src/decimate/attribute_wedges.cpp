#include "decimate/attribute_wedges.hpp"

#include <algorithm>
#include <cmath>

#include "core/union_find.hpp"

namespace topstoc {

namespace {

// Equal up to rounding (values written twice through different paths), NaN equal to NaN.
bool same_value(double a, double b) {
  if (std::isnan(a) || std::isnan(b)) return std::isnan(a) && std::isnan(b);
  return std::fabs(a - b) <= 1e-6 * (1.0 + std::max(std::fabs(a), std::fabs(b)));
}

}  // namespace

std::vector<uint8_t> corner_wedges(const Mesh& mesh, const CornerAttributes& attributes,
                                   const std::vector<int32_t>& label, int32_t clusters, int max_wedges) {
  const auto& faces = mesh.faces();
  const auto& face_source = mesh.face_source();
  const int channels = attributes.channels;
  const int32_t m = mesh.num_faces(), n = mesh.num_vertices();
  // The caller's values of the prepared mesh's corner c.
  auto values = [&](int32_t c) { return attributes.values + (3 * size_t(face_source[c / 3]) + c % 3) * channels; };
  auto corner_at = [&](int32_t f, int32_t v) {
    int32_t j = 0;
    while (faces[3 * size_t(f) + j] != v) ++j;
    return 3 * f + j;
  };
  UnionFind sets(3 * m);  // its roots are each set's smallest corner
  std::vector<int32_t> around;
  for (int32_t v = 0; v < n; ++v) {
    if (label[v] < 0) continue;
    around.clear();
    mesh.for_each_face(v, [&](int32_t f) { around.push_back(corner_at(f, v)); });
    for (size_t a = 0; a < around.size(); ++a)
      for (size_t b = 0; b < a; ++b) {
        const double *x = values(around[a]), *y = values(around[b]);
        bool same = true;
        for (int i = 0; i < channels && same; ++i) same = same_value(x[i], y[i]);
        if (same) sets.unite(around[a], around[b]);
      }
  }
  for (int32_t f = 0; f < m; ++f) {
    const int32_t* t = &faces[3 * size_t(f)];
    for (int j = 0; j < 3; ++j)
      for (int k = 0; k < j; ++k)
        if (label[t[j]] >= 0 && label[t[j]] == label[t[k]]) sets.unite(3 * f + j, 3 * f + k);
  }
  // Slots in corner order: a set's first corner numbers it within its cluster.
  std::vector<uint8_t> wedge(3 * size_t(m), 0), count(size_t(clusters), 0);
  for (int32_t c = 0; c < 3 * m; ++c) {
    const int32_t cluster = label[faces[c]];
    if (cluster < 0) continue;
    const int32_t root = sets.find(c);
    if (root == c) {
      wedge[c] = uint8_t(std::min<int>(count[cluster], max_wedges - 1));
      if (count[cluster] < max_wedges) ++count[cluster];
    } else {
      wedge[c] = wedge[root];
    }
  }
  return wedge;
}

}  // namespace topstoc
