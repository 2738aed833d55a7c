#include "topstoc/complex.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <string>

namespace topstoc {

namespace {

constexpr int64_t kMaxSides = (int64_t(1) << 30) - 1;  // side_twin stores 2 * side in an int32

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
template <class T>
void sort_bucket(T* begin, T* end) {
  if (end - begin > 24) {
    std::sort(begin, end);
    return;
  }
  for (T* i = begin + 1; i < end; ++i) {
    T x = *i;
    T* j = i;
    for (; j > begin && x < *(j - 1); --j) *j = *(j - 1);
    *j = x;
  }
}

void check_input(const double* positions, int32_t n, const int32_t* triangles, int64_t m, const int32_t* edges,
                 int64_t k) {
  if (n < 0) throw std::invalid_argument("number of vertices is negative");
  if (m < 0 || k < 0) throw std::invalid_argument("number of triangles or edges is negative");
  if (3 * m > kMaxSides) throw std::invalid_argument("complex is too large: more than 2^30 / 3 triangles");
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

// Fills edges, incidences and twins of `out`, whose triangles (three distinct vertices each) and
// num_vertices are set; wires are extra vertex pairs (lower first).
void build_edges(SimplicialComplex& out, const std::vector<int32_t>& wires) {
  const int32_t n = out.num_vertices;
  const int32_t num_sides = static_cast<int32_t>(out.triangles.size());
  const int32_t* tri = out.triangles.data();

  // Each side and wire becomes an entry in the bucket of its lower vertex: the higher vertex in
  // the top 32 bits, then (side + 1) and whether the side runs from lower to higher (wires: 0).
  // Sorting a bucket groups each edge's entries.
  std::vector<int32_t> offsets(size_t(n) + 1, 0);
  out.vertex_triangles.assign(n, 0);
  out.vertex_side.assign(n, -1);
  for (int32_t s = 0; s < num_sides; ++s) {
    const int32_t a = tri[s], b = tri[SimplicialComplex::next_side(s)];
    ++offsets[a < b ? a : b];
    if (out.vertex_triangles[a]++ == 0) out.vertex_side[a] = s;
  }
  for (size_t i = 0; i < wires.size(); i += 2) ++offsets[wires[i]];
  exclusive_scan(offsets, "edge incidences");
  std::vector<uint64_t> entries(offsets[n]);
  {
    std::vector<int32_t> fill(offsets.begin(), offsets.end() - 1);
    for (int32_t s = 0; s < num_sides; ++s) {
      const int32_t a = tri[s], b = tri[SimplicialComplex::next_side(s)];
      const uint32_t low = (uint32_t(s + 1) << 1) | (a < b ? 1u : 0u);
      entries[fill[a < b ? a : b]++] = (uint64_t(uint32_t(a < b ? b : a)) << 32) | low;
    }
    for (size_t i = 0; i < wires.size(); i += 2) entries[fill[wires[i]]++] = uint64_t(uint32_t(wires[i + 1])) << 32;
  }

  // Per vertex: sort its bucket and count distinct edges.
  std::vector<int32_t> edge_base(size_t(n) + 1, 0);
#pragma omp parallel for schedule(dynamic, 8192)
  for (int32_t v = 0; v < n; ++v) {
    uint64_t* begin = entries.data() + offsets[v];
    uint64_t* end = entries.data() + offsets[v + 1];
    sort_bucket(begin, end);
    int32_t distinct = 0;
    for (uint64_t* i = begin; i < end; ++i)
      if (i == begin || (*i >> 32) != (*(i - 1) >> 32)) ++distinct;
    edge_base[v] = distinct;
  }
  exclusive_scan(edge_base, "edges");
  const int32_t num_edges = edge_base[n];
  out.edges.resize(2 * size_t(num_edges));
  out.edge_triangles.assign(num_edges, 0);
  out.triangle_edges.resize(num_sides);
  out.side_twin.resize(num_sides);

  // Number the edges (lower vertex, then higher) and link each edge's sides.
#pragma omp parallel for schedule(dynamic, 8192)
  for (int32_t v = 0; v < n; ++v) {
    int32_t edge = edge_base[v];
    for (int32_t i = offsets[v]; i < offsets[v + 1]; ++edge) {
      const uint32_t hi = uint32_t(entries[i] >> 32);
      int32_t j = i;
      while (j < offsets[v + 1] && uint32_t(entries[j] >> 32) == hi) ++j;
      out.edges[2 * size_t(edge)] = v;
      out.edges[2 * size_t(edge) + 1] = int32_t(hi);
      // Wires (low word 0) sort first; the rest are sides.
      int32_t first_side = i;
      while (first_side < j && uint32_t(entries[first_side]) == 0) ++first_side;
      const int32_t count = j - first_side;
      out.edge_triangles[edge] = count;
      for (int32_t k = first_side; k < j; ++k) {
        const uint32_t low = uint32_t(entries[k]);
        const int32_t s = int32_t(low >> 1) - 1;
        out.triangle_edges[s] = edge;
        if (count == 1) {
          out.side_twin[s] = SimplicialComplex::kOpenSide;
        } else if (count == 2) {
          const uint32_t other = uint32_t(entries[k == first_side ? k + 1 : first_side]);
          const int32_t same_direction = ((other ^ low) & 1u) ? 0 : 1;
          out.side_twin[s] = 2 * (int32_t(other >> 1) - 1) + same_direction;
        } else {
          out.side_twin[s] = SimplicialComplex::kFinSide;
        }
      }
      i = j;
    }
  }
}

// Triangles whose vertex set repeats an earlier triangle's: either all three sides are twinned
// with one and the same triangle, or they meet it at an edge of three or more triangles with the
// same opposite vertex. Returns the later triangle of each such pair.
std::vector<uint8_t> find_duplicates(const SimplicialComplex& k, int32_t& count) {
  const int32_t m = k.num_triangles();
  std::vector<uint8_t> duplicate(m, 0);
  count = 0;
  for (int32_t t = 0; t < m; ++t) {
    const int32_t a = k.side_twin[3 * t], b = k.side_twin[3 * t + 1], c = k.side_twin[3 * t + 2];
    if (a < 0 || b < 0 || c < 0) continue;
    const int32_t u = (a >> 1) / 3;
    if (u < t && u == (b >> 1) / 3 && u == (c >> 1) / 3) duplicate[t] = 1;
  }
  // Edges of three or more triangles: compare opposite vertices within each edge.
  std::vector<std::pair<int32_t, int32_t>> fins;  // (edge, side)
  for (int32_t s = 0; s < 3 * m; ++s)
    if (k.side_twin[s] == SimplicialComplex::kFinSide) fins.emplace_back(k.triangle_edges[s], s);
  std::sort(fins.begin(), fins.end());
  for (size_t i = 0; i < fins.size();) {
    size_t j = i;
    while (j < fins.size() && fins[j].first == fins[i].first) ++j;
    for (size_t x = i; x < j; ++x)
      for (size_t y = i; y < x; ++y) {
        const int32_t sx = fins[x].second, sy = fins[y].second;  // sy < sx
        if (k.triangles[SimplicialComplex::previous_side(sx)] == k.triangles[SimplicialComplex::previous_side(sy)])
          duplicate[sx / 3] = 1;
      }
    i = j;
  }
  for (auto d : duplicate) count += d;
  return duplicate;
}

}  // namespace

SimplicialComplex build_complex(const double* positions, int32_t num_vertices, const int32_t* triangles,
                                int64_t num_triangles, const int32_t* edges, int64_t num_edges) {
  check_input(positions, num_vertices, triangles, num_triangles, edges, num_edges);
  const int32_t m = static_cast<int32_t>(num_triangles);
  SimplicialComplex out;
  out.num_vertices = num_vertices;
  out.input_triangles = m;
  out.input_edges = static_cast<int32_t>(num_edges);

  // Collapsed triangles become wire edges (or nothing beyond their vertex); the others are
  // 2-simplex candidates, kept in the caller's order.
  std::vector<int32_t> wires;  // vertex pairs, lower first
  out.triangles.reserve(3 * size_t(m));
  out.triangle_source.reserve(m);
  for (int32_t t = 0; t < m; ++t) {
    const int32_t* x = triangles + 3 * size_t(t);
    if (x[0] != x[1] && x[1] != x[2] && x[2] != x[0]) {
      out.triangles.insert(out.triangles.end(), x, x + 3);
      out.triangle_source.push_back(t);
      continue;
    }
    ++out.collapsed_triangles;
    std::array<int32_t, 3> s = {x[0], x[1], x[2]};
    std::sort(s.begin(), s.end());
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
  build_edges(out, wires);

  // Duplicates are rare: when there are any, drop them and build again.
  int32_t duplicates = 0;
  const auto duplicate = find_duplicates(out, duplicates);
  if (duplicates > 0) {
    std::vector<int32_t> kept, source;
    kept.reserve(out.triangles.size());
    for (int32_t t = 0; t < out.num_triangles(); ++t) {
      if (duplicate[t]) continue;
      kept.insert(kept.end(), out.triangles.begin() + 3 * size_t(t), out.triangles.begin() + 3 * size_t(t) + 3);
      source.push_back(out.triangle_source[t]);
    }
    out.triangles.swap(kept);
    out.triangle_source.swap(source);
    out.duplicate_triangles = duplicates;
    build_edges(out, wires);
  }
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
