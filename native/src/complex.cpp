#include "topstoc/complex.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <string>

namespace topstoc {

namespace {

std::array<int32_t, 3> sorted_corners(const int32_t* t) {
  std::array<int32_t, 3> s = {t[0], t[1], t[2]};
  if (s[0] > s[1]) std::swap(s[0], s[1]);
  if (s[1] > s[2]) std::swap(s[1], s[2]);
  if (s[0] > s[1]) std::swap(s[0], s[1]);
  return s;
}

// Prefix sums in place: counts[i] becomes the sum of counts[0..i); counts.back() the total.
void exclusive_scan(std::vector<int32_t>& counts, const char* what) {
  int64_t sum = 0;
  for (auto& c : counts) {
    const int64_t x = c;
    c = static_cast<int32_t>(sum);
    sum += x;
  }
  if (sum > INT32_MAX) throw std::invalid_argument(std::string("complex is too large: more than 2^31 ") + what);
}

// Sorts a small range in place (insertion sort; buckets here hold a handful of entries), falling
// back to std::sort for the rare large bucket (a vertex shared by many triangles).
template <class T, class Less>
void sort_bucket(T* begin, T* end, Less less) {
  if (end - begin > 24) {
    std::sort(begin, end, less);
    return;
  }
  for (T* i = begin + 1; i < end; ++i) {
    T x = *i;
    T* j = i;
    for (; j > begin && less(x, *(j - 1)); --j) *j = *(j - 1);
    *j = x;
  }
}

void check_input(const double* positions, int32_t n, const int32_t* triangles, int64_t m, const int32_t* edges,
                 int64_t k) {
  if (n < 0) throw std::invalid_argument("number of vertices is negative");
  if (m < 0 || k < 0) throw std::invalid_argument("number of triangles or edges is negative");
  if (m > INT32_MAX / 3) throw std::invalid_argument("complex is too large: more than 2^31 / 3 triangles");
  if (k > INT32_MAX / 2) throw std::invalid_argument("complex is too large: more than 2^31 / 2 edges");
  if (positions) {
    for (int32_t v = 0; v < n; ++v) {
      const double* p = positions + 3 * size_t(v);
      if (!std::isfinite(p[0]) || !std::isfinite(p[1]) || !std::isfinite(p[2])) {
        std::ostringstream s;
        s << "vertex " << v << " has a non-finite coordinate (" << p[0] << ", " << p[1] << ", " << p[2] << ")";
        throw std::invalid_argument(s.str());
      }
    }
  }
  for (int64_t t = 0; t < m; ++t)
    for (int c = 0; c < 3; ++c) {
      const int32_t v = triangles[3 * t + c];
      if (v < 0 || v >= n)
        throw std::invalid_argument("triangle " + std::to_string(t) + " refers to vertex " + std::to_string(v) +
                                    ", but vertex indices must lie in [0, " + std::to_string(n) + ")");
    }
  for (int64_t e = 0; e < k; ++e)
    for (int c = 0; c < 2; ++c) {
      const int32_t v = edges[2 * e + c];
      if (v < 0 || v >= n)
        throw std::invalid_argument("edge " + std::to_string(e) + " refers to vertex " + std::to_string(v) +
                                    ", but vertex indices must lie in [0, " + std::to_string(n) + ")");
    }
}

}  // namespace

SimplicialComplex build_complex(const double* positions, int32_t num_vertices, const int32_t* triangles,
                                int64_t num_triangles, const int32_t* edges, int64_t num_edges) {
  check_input(positions, num_vertices, triangles, num_triangles, edges, num_edges);
  const int32_t n = num_vertices;
  const int32_t m = static_cast<int32_t>(num_triangles);
  SimplicialComplex out;
  out.num_vertices = n;
  out.input_triangles = m;
  out.input_edges = static_cast<int32_t>(num_edges);

  // 1. Collapsed triangles become wire edges (or nothing beyond their vertex); the others are
  // candidates for 2-simplices.
  std::vector<int32_t> wires;  // vertex pairs, lower first
  std::vector<int32_t> candidates;
  candidates.reserve(m);
  for (int32_t t = 0; t < m; ++t) {
    const auto s = sorted_corners(triangles + 3 * size_t(t));
    if (s[0] != s[1] && s[1] != s[2]) {
      candidates.push_back(t);
      continue;
    }
    ++out.collapsed_triangles;
    if (s[0] != s[2]) {  // two distinct vertices: the edge between them
      wires.push_back(s[0]);
      wires.push_back(s[0] == s[1] ? s[2] : s[1]);
    }
  }
  for (int64_t e = 0; e < num_edges; ++e) {
    const int32_t a = edges[2 * e], b = edges[2 * e + 1];
    if (a == b) continue;  // a vertex, already in the complex
    wires.push_back(std::min(a, b));
    wires.push_back(std::max(a, b));
  }

  // 2. Duplicates: bucket the candidates by their lowest vertex, sort each small bucket by the
  // other two (then by index, so the first occurrence is kept) and drop repeats.
  std::vector<uint8_t> duplicate(m, 0);
  {
    std::vector<int32_t> offsets(n + 1, 0);
    for (int32_t t : candidates) ++offsets[sorted_corners(triangles + 3 * size_t(t))[0]];
    exclusive_scan(offsets, "triangles");
    std::vector<int32_t> bucket(candidates.size());
    {
      std::vector<int32_t> fill(offsets.begin(), offsets.end() - 1);
      for (int32_t t : candidates) bucket[fill[sorted_corners(triangles + 3 * size_t(t))[0]]++] = t;
    }
    auto key = [&](int32_t t) {
      const auto s = sorted_corners(triangles + 3 * size_t(t));
      return (uint64_t(uint32_t(s[1])) << 32) | uint32_t(s[2]);
    };
#pragma omp parallel for schedule(dynamic, 4096)
    for (int32_t v = 0; v < n; ++v) {
      int32_t* begin = bucket.data() + offsets[v];
      int32_t* end = bucket.data() + offsets[v + 1];
      if (end - begin < 2) continue;
      sort_bucket(begin, end, [&](int32_t a, int32_t b) {
        const uint64_t ka = key(a), kb = key(b);
        return ka < kb || (ka == kb && a < b);
      });
      for (int32_t* i = begin + 1; i < end; ++i)
        if (key(*i) == key(*(i - 1))) duplicate[*i] = 1;
    }
  }
  out.triangles.reserve(3 * candidates.size());
  out.triangle_source.reserve(candidates.size());
  for (int32_t t : candidates) {
    if (duplicate[t]) {
      ++out.duplicate_triangles;
      continue;
    }
    out.triangles.insert(out.triangles.end(), triangles + 3 * size_t(t), triangles + 3 * size_t(t) + 3);
    out.triangle_source.push_back(t);
  }
  const int32_t num_sides = 3 * out.num_triangles();

  // 3. Edges: every triangle side and wire edge, bucketed by its lower vertex. An entry packs the
  // higher vertex and the side (side + 1, 0 for a wire) so that sorting a bucket groups each
  // edge's sides in increasing order.
  const int64_t num_entries = int64_t(num_sides) + int64_t(wires.size() / 2);
  if (num_entries > INT32_MAX) throw std::invalid_argument("complex is too large: more than 2^31 edge incidences");
  std::vector<int32_t> offsets(n + 1, 0);
  for (int32_t s = 0; s < num_sides; ++s) {
    const int32_t a = out.triangles[s], b = out.triangles[s - s % 3 + (s % 3 + 1) % 3];
    ++offsets[std::min(a, b)];
  }
  for (size_t i = 0; i < wires.size(); i += 2) ++offsets[wires[i]];
  exclusive_scan(offsets, "edge incidences");
  std::vector<uint64_t> entries(num_entries);
  {
    std::vector<int32_t> fill(offsets.begin(), offsets.end() - 1);
    for (int32_t s = 0; s < num_sides; ++s) {
      const int32_t a = out.triangles[s], b = out.triangles[s - s % 3 + (s % 3 + 1) % 3];
      entries[fill[std::min(a, b)]++] = (uint64_t(uint32_t(std::max(a, b))) << 32) | uint32_t(s + 1);
    }
    for (size_t i = 0; i < wires.size(); i += 2) entries[fill[wires[i]]++] = uint64_t(uint32_t(wires[i + 1])) << 32;
  }
  // Per vertex: sort its bucket, count distinct edges and triangle sides.
  std::vector<int32_t> edge_base(n + 1, 0), side_base(n + 1, 0);
#pragma omp parallel for schedule(dynamic, 4096)
  for (int32_t v = 0; v < n; ++v) {
    uint64_t* begin = entries.data() + offsets[v];
    uint64_t* end = entries.data() + offsets[v + 1];
    sort_bucket(begin, end, [](uint64_t a, uint64_t b) { return a < b; });
    int32_t distinct = 0, sides = 0;
    for (uint64_t* i = begin; i < end; ++i) {
      if (i == begin || (*i >> 32) != (*(i - 1) >> 32)) ++distinct;
      if (uint32_t(*i) != 0) ++sides;
    }
    edge_base[v] = distinct;
    side_base[v] = sides;
  }
  exclusive_scan(edge_base, "edges");
  exclusive_scan(side_base, "edge incidences");
  const int32_t num_edges_out = edge_base[n];
  out.edges.resize(2 * size_t(num_edges_out));
  out.edge_side_offsets.resize(size_t(num_edges_out) + 1);
  out.edge_sides.resize(num_sides);
  out.triangle_edges.resize(num_sides);
#pragma omp parallel for schedule(dynamic, 4096)
  for (int32_t v = 0; v < n; ++v) {
    int32_t edge = edge_base[v] - 1, side_at = side_base[v];
    for (int32_t i = offsets[v]; i < offsets[v + 1]; ++i) {
      const uint64_t x = entries[i];
      if (i == offsets[v] || (x >> 32) != (entries[i - 1] >> 32)) {
        ++edge;
        out.edges[2 * size_t(edge)] = v;
        out.edges[2 * size_t(edge) + 1] = int32_t(x >> 32);
        out.edge_side_offsets[edge] = side_at;
      }
      const uint32_t side_plus_one = uint32_t(x);
      if (side_plus_one != 0) {
        out.edge_sides[side_at++] = int32_t(side_plus_one - 1);
        out.triangle_edges[side_plus_one - 1] = edge;
      }
    }
  }
  out.edge_side_offsets[num_edges_out] = num_sides;
  return out;
}

void vertex_edges(const SimplicialComplex& complex, std::vector<int32_t>& offsets, std::vector<int32_t>& incident) {
  const int32_t n = complex.num_vertices, num_edges = complex.num_edges();
  offsets.assign(size_t(n) + 1, 0);
  for (int32_t v : complex.edges) ++offsets[v];
  exclusive_scan(offsets, "edge incidences");
  incident.resize(complex.edges.size());
  std::vector<int32_t> fill(offsets.begin(), offsets.end() - 1);
  for (int32_t e = 0; e < num_edges; ++e) {
    incident[fill[complex.edges[2 * size_t(e)]]++] = e;
    incident[fill[complex.edges[2 * size_t(e) + 1]]++] = e;
  }
}

}  // namespace topstoc
