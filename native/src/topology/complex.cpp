#include "topstoc/topology/complex.hpp"

#include "core/morton_order.hpp"
#include "topstoc/core/validate.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <numeric>
#include <stdexcept>
#include <string>

#include "core/per_thread.hpp"
#include "topstoc/core/parallel.hpp"

namespace topstoc {

namespace {

constexpr int64_t kMaxSides = (int64_t(1) << 30) - 1;  // side_twin stores 2 * side in an int32

int32_t pass_threads(int64_t items) { return items >= kParallelMinimum ? max_threads() : 1; }

// Stable counting sort of items 0..count-1 into buckets 0..num_buckets-1: count_item(i, hist)
// increments hist[bucket of i]; place(i, hist) writes item i at hist[bucket of i]++. Runs on
// contiguous chunks, one histogram per chunk (in `histograms`, reused memory), so the result is
// the serial one. `offsets` receives the bucket starts (num_buckets + 1 entries).
template <class CountItem, class Place>
void counting_sort(int64_t count, int32_t num_buckets, CountItem count_item, Place place, std::vector<int32_t>& offsets,
                   std::vector<int32_t>& histograms) {
  const int32_t chunks = pass_threads(count);
  histograms.assign(size_t(chunks) * size_t(num_buckets), 0);
  auto hist = [&](int32_t c) { return histograms.data() + size_t(c) * size_t(num_buckets); };
  parallel_for(0, chunks, parallel_if(chunks > 1), [&](int32_t c) {
    for (int64_t i = count * c / chunks; i < count * (c + 1) / chunks; ++i) count_item(i, hist(c));
  });
  offsets.assign(size_t(num_buckets) + 1, 0);
  int64_t running = 0;
  for (int32_t b = 0; b < num_buckets; ++b) {
    offsets[b] = static_cast<int32_t>(running);
    for (int32_t c = 0; c < chunks; ++c) {
      const int32_t x = hist(c)[b];
      hist(c)[b] = static_cast<int32_t>(running);
      running += x;
    }
  }
  if (running > INT32_MAX) throw std::invalid_argument("complex is too large: more than 2^31 incidences");
  offsets[num_buckets] = static_cast<int32_t>(running);
  parallel_for(0, chunks, parallel_if(chunks > 1), [&](int32_t c) {
    for (int64_t i = count * c / chunks; i < count * (c + 1) / chunks; ++i) place(i, hist(c));
  });
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

// Sizes and coordinates; the triangles' indices are checked while they are copied, then the
// edges' (build_complex), so that the first problem in this order is the one reported.
void check_sizes_and_positions(const double* positions, int32_t n, int64_t m, int64_t k) {
  if (n < 0) throw std::invalid_argument("number of vertices is negative");
  if (m < 0 || k < 0) throw std::invalid_argument("number of triangles or edges is negative");
  if (3 * m > kMaxSides) throw std::invalid_argument("complex is too large: more than 2^30 / 3 triangles");
  if (k > INT32_MAX / 2) throw std::invalid_argument("complex is too large: more than 2^31 / 2 edges");
  if (positions) require_finite_positions(positions, n);
}

// Locality of the caller's arrays, counted while the triangles are copied (one pass): the
// caller's numbering has it when most triangles span nearby vertex ids; the triangle order has
// it when consecutive triangles mostly lie close together: they share a vertex or have nearby
// lowest vertices (meshes written face by face by modellers, scanners' meshers, subdivision),
// as opposed to shuffled ones.
struct LocalityCount {
  int64_t triangles = 0, spanning_nearby_ids = 0, close_to_previous = 0;
  const int32_t* previous = nullptr;
  // Each answer is settled once its count or its complement passes half of `at_most` (the
  // caller's triangle count bounds the final one): later triangles are then not examined.
  int64_t at_most = 0;
  bool numbering_settled = false, order_settled = false;

  explicit LocalityCount(int64_t at_most) : at_most(at_most) {}

  void add(const int32_t* b) {
    ++triangles;
    if (!numbering_settled) {
      spanning_nearby_ids += int64_t(std::max({b[0], b[1], b[2]})) - std::min({b[0], b[1], b[2]}) <= 1024;
      numbering_settled = 2 * spanning_nearby_ids >= at_most || 2 * (triangles - spanning_nearby_ids) > at_most;
    }
    if (order_settled) return;
    if (const int32_t* a = previous) {
      const bool share = a[0] == b[0] || a[0] == b[1] || a[0] == b[2] || a[1] == b[0] || a[1] == b[1] ||
                         a[1] == b[2] || a[2] == b[0] || a[2] == b[1] || a[2] == b[2];
      const int64_t jump = int64_t(std::min({a[0], a[1], a[2]})) - std::min({b[0], b[1], b[2]});
      close_to_previous += share || (jump >= -256 && jump <= 256);
      order_settled = 2 * close_to_previous >= at_most || 2 * (triangles - 1 - close_to_previous) > at_most;
    }
    previous = b;
  }
  // Once settled, the count stands on the side of the answer it settled on for any final count.
  bool local_numbering() const { return 2 * spanning_nearby_ids >= (numbering_settled ? at_most : triangles); }
  bool coherent_triangle_order() const { return 2 * close_to_previous >= (order_settled ? at_most : triangles); }
};

// Renumbers the vertices of `out` (and the wires) in order of first appearance in its
// triangles, then the unused ones: one pass that numbers each vertex when it is first met and
// rewrites the corners as it goes (the triangle order is kept).
void renumber_by_first_appearance(SimplicialComplex& out, std::vector<int32_t>& wires) {
  const int32_t n = out.num_vertices;
  auto& index = out.vertex_index;
  auto& source = out.vertex_source;
  index.assign(n, -1);
  source.resize(n);
  int32_t next = 0;
  for (int32_t& v : out.triangles) {
    int32_t& i = index[v];
    if (i < 0) {
      i = next++;
      source[i] = v;
    }
    v = i;
  }
  for (int32_t v = 0; v < n; ++v)
    if (index[v] < 0) {
      index[v] = next++;
      source[index[v]] = v;
    }
  for (size_t i = 0; i < wires.size(); i += 2) {
    const int32_t a = index[wires[i]], b = index[wires[i + 1]];
    wires[i] = std::min(a, b);
    wires[i + 1] = std::max(a, b);
  }
}

// Renumbers the vertices of `out` (and the wires) by `order` and sorts the triangles by their
// lowest vertex (stable: ties keep the caller's order).
void renumber_and_sort(SimplicialComplex& out, std::vector<int32_t> order, std::vector<int32_t>& wires) {
  const int32_t n = out.num_vertices, m = out.num_triangles();
  out.vertex_index.resize(n);
  for (int32_t i = 0; i < n; ++i) out.vertex_index[order[i]] = i;
  out.vertex_source = std::move(order);
  const auto& index = out.vertex_index;
  for (size_t i = 0; i < wires.size(); i += 2) {
    const int32_t a = index[wires[i]], b = index[wires[i + 1]];
    wires[i] = std::min(a, b);
    wires[i + 1] = std::max(a, b);
  }
  parallel_for(0, out.triangles.size(), kParallelMinimum, [&](size_t i) { out.triangles[i] = index[out.triangles[i]]; });
  auto lowest = [&](int64_t t) {
    const int32_t* x = &out.triangles[3 * size_t(t)];
    return std::min({x[0], x[1], x[2]});
  };
  std::vector<int32_t> triangles(out.triangles.size()), source(m), offsets;
  counting_sort(
      m, n, [&](int64_t t, int32_t* hist) { ++hist[lowest(t)]; },
      [&](int64_t t, int32_t* hist) {
        const int32_t at = hist[lowest(t)]++;
        for (int c = 0; c < 3; ++c) triangles[3 * size_t(at) + c] = out.triangles[3 * size_t(t) + c];
        source[at] = out.triangle_source[t];
      },
      offsets, out.scratch.histograms);
  out.triangles.swap(triangles);
  out.triangle_source.swap(source);
}

// The sides and wires of the edges whose lower vertex is v, as sorted entries: the higher
// vertex in the top 32 bits, then (side + 1) and whether the side runs from lower to higher
// (wires: low word 0, so they sort first in their edge). Read from v's star: each side s
// starting at v gives the edge to its end (s itself) and the edge to its triangle's third vertex
// (the side before s, which ends at v). `entries` must hold 2 * (triangles at v) + (wires at v).
// Returns the number of entries.
int32_t edges_at(const SimplicialComplex& k, int32_t v, const int32_t* star, const int32_t* star_offsets,
                 const int32_t* wire_ends, const int32_t* wire_offsets, uint64_t* entries) {
  const int32_t* tri = k.triangles.data();
  int32_t count = 0;
  if (wire_offsets)
    for (int32_t i = wire_offsets[v]; i < wire_offsets[v + 1]; ++i) entries[count++] = uint64_t(uint32_t(wire_ends[i])) << 32;
  for (int32_t i = star_offsets[v]; i < star_offsets[v + 1]; ++i) {
    const int32_t s = star[i];
    const int32_t corner = s % 3, first = s - corner;
    const int32_t end = tri[first + (corner == 2 ? 0 : corner + 1)];
    const int32_t before = first + (corner == 0 ? 2 : corner - 1);  // runs from the third vertex to v
    const int32_t third = tri[before];
    if (end > v) entries[count++] = (uint64_t(uint32_t(end)) << 32) | (uint32_t(s + 1) << 1) | 1u;
    if (third > v) entries[count++] = (uint64_t(uint32_t(third)) << 32) | (uint32_t(before + 1) << 1);
  }
  sort_bucket(entries, entries + count);
  return count;
}

// Fills the twins, fins, wires and vertex incidences of `out`, whose triangles (three distinct
// vertices each) and num_vertices are set; wires are extra vertex pairs (lower first).
//
// Edges are found around vertices rather than by bucketing every side by its lower vertex: the
// star of each vertex (the sides starting there) is one counting sort of 4-byte side ids, and
// it also gives the triangle count and first side of every vertex. Each vertex then lists the
// edges to its higher neighbours from its star (edges_at) and links their sides.
void link_sides(SimplicialComplex& out, const std::vector<int32_t>& wires) {
  const int32_t n = out.num_vertices;
  const int32_t num_sides = out.num_sides();
  const int32_t* tri = out.triangles.data();

  auto& star = out.vertex_star;
  auto& star_offsets = out.vertex_star_offsets;
  star.resize(num_sides);
  counting_sort(
      num_sides, n, [&](int64_t s, int32_t* hist) { ++hist[tri[s]]; },
      [&](int64_t s, int32_t* hist) { star[hist[tri[s]]++] = int32_t(s); }, star_offsets, out.scratch.histograms);
  // Wires by lower vertex (rare; serial).
  const int64_t num_wires = static_cast<int64_t>(wires.size() / 2);
  std::vector<int32_t> wire_ends, wire_offsets;
  if (num_wires > 0) {
    wire_ends.resize(num_wires);
    counting_sort(
        num_wires, n, [&](int64_t w, int32_t* hist) { ++hist[wires[2 * w]]; },
        [&](int64_t w, int32_t* hist) { wire_ends[hist[wires[2 * w]]++] = wires[2 * w + 1]; }, wire_offsets,
        out.scratch.histograms);
  }
  const int32_t* wire_at = num_wires > 0 ? wire_offsets.data() : nullptr;

  // Triangles at each vertex, the first side starting there, and the largest entry list.
  out.vertex_triangles.resize(n);
  out.vertex_side.resize(n);
  int32_t most_entries = 0;
  for (int32_t v = 0; v < n; ++v) {
    const int32_t triangles = star_offsets[v + 1] - star_offsets[v];
    out.vertex_triangles[v] = triangles;
    out.vertex_side[v] = triangles ? star[star_offsets[v]] : -1;
    most_entries = std::max(most_entries, 2 * triangles + (wire_at ? wire_at[v + 1] - wire_at[v] : 0));
  }

  // Per vertex: list its edges and link the sides of each. Vertices holding an edge with no
  // triangle or with three and more (rare) are flagged and read again serially below, so the
  // parallel loop allocates nothing.
  out.side_twin.resize(num_sides);
  std::vector<uint8_t> special(n, 0);
  const int32_t threads = pass_threads(num_sides);
  std::vector<uint64_t> scratch(size_t(threads) * size_t(most_entries));
  PerThread<int64_t> edges_found(threads);
  parallel_for_dynamic(0, n, 8192, parallel_if(threads > 1), [&](int32_t v) {
    int64_t& num_edges = edges_found.mine();
    uint64_t* begin = scratch.data() + size_t(thread_index()) * size_t(most_entries);
    uint64_t* end =
        begin + edges_at(out, v, star.data(), star_offsets.data(), wire_ends.data(), wire_at, begin);
    for (uint64_t* i = begin; i < end;) {
      const uint32_t hi = uint32_t(*i >> 32);
      uint64_t* j = i;
      while (j < end && uint32_t(*j >> 32) == hi) ++j;
      ++num_edges;
      uint64_t* first_side = i;  // wires (low word 0) sort first
      while (first_side < j && uint32_t(*first_side) == 0) ++first_side;
      const int64_t count = j - first_side;
      if (count == 1) {
        out.side_twin[int32_t(uint32_t(*first_side) >> 1) - 1] = SimplicialComplex::kOpenSide;
      } else if (count == 2) {
        const uint32_t x = uint32_t(first_side[0]), y = uint32_t(first_side[1]);
        const int32_t same_direction = ((x ^ y) & 1u) ? 0 : 1;
        out.side_twin[int32_t(x >> 1) - 1] = 2 * (int32_t(y >> 1) - 1) + same_direction;
        out.side_twin[int32_t(y >> 1) - 1] = 2 * (int32_t(x >> 1) - 1) + same_direction;
      } else {
        special[v] = 1;
        for (uint64_t* k = first_side; k < j; ++k)
          out.side_twin[int32_t(uint32_t(*k) >> 1) - 1] = SimplicialComplex::kFinSide;
      }
      i = j;
    }
  });
  int64_t num_edges = 0;
  for (int t = 0; t < threads; ++t) num_edges += edges_found[t];
  if (num_edges > INT32_MAX) throw std::invalid_argument("complex is too large: more than 2^31 edges");
  out.num_edges = static_cast<int32_t>(num_edges);

  // Fins (edges of 3+ triangles, with their sides) and lone wires, in edge order.
  out.fin_edges.clear();
  out.fin_offsets.assign(1, 0);
  out.fin_sides.clear();
  out.wire_edges.clear();
  for (int32_t v = 0; v < n; ++v) {
    if (!special[v]) continue;
    const uint64_t* begin = scratch.data();
    const uint64_t* end = begin + edges_at(out, v, star.data(), star_offsets.data(), wire_ends.data(), wire_at, scratch.data());
    for (const uint64_t* i = begin; i < end;) {
      const uint32_t hi = uint32_t(*i >> 32);
      const uint64_t* j = i;
      while (j < end && uint32_t(*j >> 32) == hi) ++j;
      const uint64_t* first_side = i;
      while (first_side < j && uint32_t(*first_side) == 0) ++first_side;
      if (first_side == j) {
        out.wire_edges.push_back(v);
        out.wire_edges.push_back(int32_t(hi));
      } else if (j - first_side >= 3) {
        out.fin_edges.push_back(v);
        out.fin_edges.push_back(int32_t(hi));
        for (const uint64_t* k = first_side; k < j; ++k) out.fin_sides.push_back(int32_t(uint32_t(*k) >> 1) - 1);
        std::sort(out.fin_sides.end() - (j - first_side), out.fin_sides.end());
        out.fin_offsets.push_back(static_cast<int32_t>(out.fin_sides.size()));
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
    const int32_t a = k.side_twin[3 * size_t(t)], b = k.side_twin[3 * size_t(t) + 1], c = k.side_twin[3 * size_t(t) + 2];
    if (a < 0 || b < 0 || c < 0) continue;
    const int32_t u = (a >> 1) / 3;
    if (u < t && u == (b >> 1) / 3 && u == (c >> 1) / 3) duplicate[t] = 1;
  }
  for (size_t f = 0; f + 1 < k.fin_offsets.size(); ++f)
    for (int32_t x = k.fin_offsets[f]; x < k.fin_offsets[f + 1]; ++x)
      for (int32_t y = k.fin_offsets[f]; y < x; ++y) {
        const int32_t sx = k.fin_sides[x], sy = k.fin_sides[y];  // sy < sx
        if (k.triangles[SimplicialComplex::previous_side(sx)] == k.triangles[SimplicialComplex::previous_side(sy)])
          duplicate[sx / 3] = 1;
      }
  for (auto d : duplicate) count += d;
  return duplicate;
}

}  // namespace

SimplicialComplex build_complex(const double* positions, int32_t num_vertices, const int32_t* triangles,
                                int64_t num_triangles, const int32_t* edges, int64_t num_edges) {
  SimplicialComplex out;
  build_complex(out, positions, num_vertices, triangles, num_triangles, edges, num_edges);
  return out;
}

void build_complex(SimplicialComplex& out, const double* positions, int32_t num_vertices, const int32_t* triangles,
                   int64_t num_triangles, const int32_t* edges, int64_t num_edges) {
  check_sizes_and_positions(positions, num_vertices, num_triangles, num_edges);
  const int32_t m = static_cast<int32_t>(num_triangles);
  // Every field is set below; vectors are resized or assigned, keeping the memory they hold.
  out.num_vertices = num_vertices;
  out.input_triangles = m;
  out.input_edges = static_cast<int32_t>(num_edges);
  out.collapsed_triangles = 0;
  out.duplicate_triangles = 0;

  // Collapsed triangles become wire edges (or nothing beyond their vertex); the others are
  // 2-simplex candidates, copied in the caller's order.
  std::vector<int32_t> wires;  // vertex pairs, lower first
  out.triangles.resize(3 * size_t(m));
  out.triangle_source.resize(m);
  LocalityCount locality(m);
  int32_t kept = 0;
  bool indices_in_range = true;  // unsigned: negative ids compare as huge
  const uint32_t n = uint32_t(num_vertices);
  for (int32_t t = 0; t < m; ++t) {
    const int32_t x[3] = {triangles[3 * size_t(t)], triangles[3 * size_t(t) + 1], triangles[3 * size_t(t) + 2]};
    indices_in_range &= (uint32_t(x[0]) < n) & (uint32_t(x[1]) < n) & (uint32_t(x[2]) < n);
    if (x[0] != x[1] && x[1] != x[2] && x[2] != x[0]) {
      int32_t* copy = &out.triangles[3 * size_t(kept)];
      for (int c = 0; c < 3; ++c) copy[c] = x[c];
      locality.add(copy);
      out.triangle_source[kept++] = t;
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
  out.triangles.resize(3 * size_t(kept));
  out.triangle_source.resize(kept);
  if (!indices_in_range) require_indices_in_range(triangles, num_triangles, 3, num_vertices, "triangle");  // throws
  require_indices_in_range(edges, num_edges, 2, num_vertices, "edge");
  for (int64_t e = 0; e < num_edges; ++e) {
    const int32_t a = edges[2 * e], b = edges[2 * e + 1];
    if (a == b) continue;  // a vertex, already in the complex
    wires.push_back(std::min(a, b));
    wires.push_back(std::max(a, b));
  }
  // Locality: keep a numbering that has it; keep a coherent triangle order and number vertices
  // as they appear in it; otherwise number vertices along a Z-order curve and sort the triangles.
  if (locality.local_numbering()) {
    out.vertex_source.resize(num_vertices);
    std::iota(out.vertex_source.begin(), out.vertex_source.end(), 0);
    out.vertex_index = out.vertex_source;
  } else if (locality.coherent_triangle_order()) {
    renumber_by_first_appearance(out, wires);
  } else if (positions) {
    renumber_and_sort(out, morton_order(positions, num_vertices), wires);
  } else {
    out.vertex_source.resize(num_vertices);
    std::iota(out.vertex_source.begin(), out.vertex_source.end(), 0);
    out.vertex_index = out.vertex_source;
  }
  link_sides(out, wires);

  // Duplicates are rare: when there are any, drop them and link again.
  int32_t duplicates = 0;
  const auto duplicate = find_duplicates(out, duplicates);
  if (duplicates > 0) {
    int32_t at = 0;
    for (int32_t t = 0; t < out.num_triangles(); ++t) {
      if (duplicate[t]) continue;
      for (int c = 0; c < 3; ++c) out.triangles[3 * size_t(at) + c] = out.triangles[3 * size_t(t) + c];
      out.triangle_source[at++] = out.triangle_source[t];
    }
    out.triangles.resize(3 * size_t(at));
    out.triangle_source.resize(at);
    out.duplicate_triangles = duplicates;
    link_sides(out, wires);
  }
}

}  // namespace topstoc
