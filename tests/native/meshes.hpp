// Small meshes built in code for the C++ tests: a torus grid (genus 1), an octahedron (genus 0)
// and a planar grid (one boundary loop), a fan lens (two wide fans), each as plain arrays; and
// random samples on them.
#pragma once

#include <cmath>
#include <algorithm>
#include <cstdint>
#include <numeric>
#include <random>
#include <vector>

#include "core/portable.hpp"

namespace topstoc_test {

struct Arrays {
  std::vector<double> positions;
  std::vector<int32_t> triangles;
  int64_t num_triangles() const { return int64_t(triangles.size() / 3); }
};

/// Torus of n x m quads (each split in two), vertex (i, j) = i * m + j; n, m >= 3.
inline Arrays torus(int32_t n, int32_t m, double major = 2.0, double minor = 0.7) {
  Arrays a;
  const double pi = std::acos(-1.0);
  for (int32_t i = 0; i < n; ++i)
    for (int32_t j = 0; j < m; ++j) {
      const double u = 2 * pi * i / n, v = 2 * pi * j / m;
      a.positions.insert(a.positions.end(), {(major + minor * std::cos(v)) * std::cos(u),
                                             (major + minor * std::cos(v)) * std::sin(u), minor * std::sin(v)});
    }
  for (int32_t i = 0; i < n; ++i)
    for (int32_t j = 0; j < m; ++j) {
      const int32_t p = i * m + j, q = ((i + 1) % n) * m + j, r = ((i + 1) % n) * m + (j + 1) % m,
                    s = i * m + (j + 1) % m;
      a.triangles.insert(a.triangles.end(), {p, q, r, p, r, s});
    }
  return a;
}

/// Planar grid of n x m quads (each split in two) in the z = 0 plane.
inline Arrays grid(int32_t n, int32_t m) {
  Arrays a;
  for (int32_t i = 0; i <= n; ++i)
    for (int32_t j = 0; j <= m; ++j) a.positions.insert(a.positions.end(), {double(i), double(j), 0.0});
  for (int32_t i = 0; i < n; ++i)
    for (int32_t j = 0; j < m; ++j) {
      const int32_t p = i * (m + 1) + j, q = p + m + 1;
      a.triangles.insert(a.triangles.end(), {p, q, q + 1, p, q + 1, p + 1});
    }
  return a;
}

/// A closed fan lens inside [-1, 1]: a rim of k vertices (radii jittered) in the plane z = 0, a
/// flat fan above it from the centre k at (0, 0, 0) and a cone below from k + 1 at (0, 0, -0.6).
inline Arrays fan_lens(int32_t k, std::mt19937& random) {
  std::uniform_real_distribution<double> jitter(0.85, 1.0);
  Arrays mesh;
  for (int32_t i = 0; i < k; ++i) {
    const double a = 2.0 * topstoc::kPi * i / k, r = 0.9 * jitter(random);
    mesh.positions.insert(mesh.positions.end(), {r * std::cos(a), r * std::sin(a), 0.0});
  }
  mesh.positions.insert(mesh.positions.end(), {0.0, 0.0, 0.0, 0.0, 0.0, -0.6});
  for (int32_t i = 0; i < k; ++i)
    mesh.triangles.insert(mesh.triangles.end(), {k, i, (i + 1) % k, k + 1, (i + 1) % k, i});
  return mesh;
}

/// Octahedron: vertex 0 = +z, 5 = -z, 1..4 around the equator.
inline Arrays octahedron() {
  Arrays a;
  a.positions = {0, 0, 1, 1, 0, 0, 0, 1, 0, -1, 0, 0, 0, -1, 0, 0, 0, -1};
  for (int32_t k = 0; k < 4; ++k) {
    const int32_t e0 = 1 + k, e1 = 1 + (k + 1) % 4;
    a.triangles.insert(a.triangles.end(), {0, e0, e1, 5, e1, e0});
  }
  return a;
}

/// `count` distinct vertex ids below n, drawn at random.
inline std::vector<int32_t> random_samples(int32_t n, int32_t count, std::mt19937& random) {
  std::vector<int32_t> ids(n);
  std::iota(ids.begin(), ids.end(), 0);
  std::shuffle(ids.begin(), ids.end(), random);
  ids.resize(count);
  return ids;
}

}  // namespace topstoc_test
