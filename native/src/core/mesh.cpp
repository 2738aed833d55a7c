#include "topstoc/core/mesh.hpp"
#include "topstoc/core/parallel.hpp"


#include <algorithm>
#include <array>
#include <cmath>
#include <numeric>
#include <stdexcept>
#include <utility>

#include "core/counting_sort.hpp"
#include "core/portable.hpp"
#include "core/sort_by_key.hpp"
#include "core/union_find.hpp"
#include "topstoc/core/validate.hpp"

namespace topstoc {

namespace {

void cross(const double* a, const double* b, const double* c, double* out) {
  const double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
  const double w[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
  out[0] = u[1] * w[2] - u[2] * w[1];
  out[1] = u[2] * w[0] - u[0] * w[2];
  out[2] = u[0] * w[1] - u[1] * w[0];
}

// The unit normal along an area-weighted sum of face normals (zero for a zero sum).
void unit_normal(const double* sum, double* out) {
  const double len = std::sqrt(sum[0] * sum[0] + sum[1] * sum[1] + sum[2] * sum[2]);
  for (int j = 0; j < 3; ++j) out[j] = len > 0 ? sum[j] / len : 0.0;
}

// Exclusive prefix sum in place over counts[0..n), with counts[n] receiving the total.
template <class Counts>
void exclusive_scan(Counts& counts) {
  int64_t sum = 0;
  for (auto& c : counts) {
    const int64_t x = c;
    c = static_cast<int32_t>(sum);
    sum += x;
  }
  if (sum > INT32_MAX) throw std::invalid_argument("mesh is too large: more than 2^31 incidences");
}

int64_t vertex_count(const std::vector<double>& positions) {
  if (positions.size() % 3 != 0) throw std::invalid_argument("positions must hold 3 coordinates per vertex");
  return int64_t(positions.size() / 3);
}

// Sorts a vertex's few link ends; valences are small, so insertion sort wins.
void sort_small(uint64_t* first, uint64_t* last) {
  if (last - first > 32) {
    std::sort(first, last);
    return;
  }
  for (uint64_t* i = first + 1; i < last; ++i) {
    const uint64_t x = *i;
    uint64_t* j = i;
    for (; j > first && *(j - 1) > x; --j) *j = *(j - 1);
    *j = x;
  }
}

// The arrays the first adjacency pass reads and writes (the Mesh's own, by reference). A
// vertex's faces are those it is not the lowest vertex of (`upper`, CSR) then its own run of the
// faces, sorted by lowest vertex: in increasing order, as vertex_faces() lists them.
struct OneRingArrays {
  const Buffer<int32_t>& faces;
  const Buffer<int32_t>& upper;
  const Buffer<int32_t>& upper_offsets;
  const Buffer<int32_t>& lowest_offsets;
  const Buffer<double>& positions;
  Buffer<int32_t>& scratch;  // each vertex's sorted neighbours, at its first face slot + its id
  Buffer<int32_t>& degree;
  Buffer<uint8_t>& manifold_vertex;
  SharedUnionFind& sets;  // components: each set's root is its lowest vertex
};

// What the first pass counts over the mesh (each edge at its lower end).
struct OneRingCounts {
  int32_t boundary = 0, nonmanifold_edges = 0, inconsistent = 0, pinched = 0, zero_area = 0;
};

// The first adjacency pass at one vertex, from its faces alone, with one thread's scratch
// lists: the link (for each face (v, a, b) the arc a -> b) gives the sorted neighbours, the
// triangles and directions of every edge at v and whether v is a manifold vertex; also the
// area-weighted normal.
class OneRingScan {
 public:
  explicit OneRingScan(const OneRingArrays& a) : a(a) {}

  void scan(int32_t v, OneRingCounts& counts) {
    const int32_t upper_first = a.upper_offsets[v], own_first = a.lowest_offsets[v];
    const int32_t above = a.upper_offsets[v + 1] - upper_first, k = above + a.lowest_offsets[v + 1] - own_first;
    a.manifold_vertex[v] = 1;
    if (k == 0) {  // isolated: no neighbours, in no component
      a.degree[v] = 0;
      return;
    }
    read_faces(v, a.upper.data() + upper_first, above, own_first, k, counts.zero_area);
    list.resize(2 * size_t(k));  // at most two neighbours per face
    int32_t* neighbours = list.data();
    const int32_t d = sort_neighbours(neighbours);
    keep_neighbours(v, upper_first + own_first, k, neighbours, d);
    const int32_t lower = int32_t(std::lower_bound(neighbours, neighbours + d, v) - neighbours);
    a.degree[v] = d;
    bool nonmanifold_edge = false, flipped = false;
    count_edges(v, neighbours, d, lower, counts, nonmanifold_edge, flipped);
    const int32_t fans = nonmanifold_edge ? 1 : count_fans(k, d, flipped);
    if (fans > 1 || nonmanifold_edge || flipped) {
      a.manifold_vertex[v] = 0;
      if (fans > 1 && !nonmanifold_edge) ++counts.pinched;  // pinched, not merely on a bad edge
    }
  }

  /// (vertex, its sorted neighbours) of the vertices with more than one neighbour per face plus one.
  std::vector<std::pair<int32_t, std::vector<int32_t>>> overflow;

 private:
  const OneRingArrays& a;
  std::vector<int32_t> list;  // this vertex's neighbours

  // A manifold vertex has as many neighbours as faces, one more on a border: its slots in
  // `scratch`, one more than its faces, hold them. More (non-manifold edges) wait in `overflow`.
  void keep_neighbours(int32_t v, int32_t first, int32_t k, const int32_t* neighbours, int32_t d) {
    if (d <= k + 1) std::copy(neighbours, neighbours + d, a.scratch.data() + size_t(first) + size_t(v));
    else overflow.emplace_back(v, std::vector<int32_t>(neighbours, neighbours + d));
  }
  std::vector<uint64_t> ends;  // (neighbour, 2 slot + (1 if the arc enters it))
  std::vector<int32_t> end_rank, in, out, next;

  // Reads v's k faces (the first `above` listed in `upper`, then the run from `own_first`): the
  // link's arc ends; counts the faces v is the lowest vertex of that have zero area.
  void read_faces(int32_t v, const int32_t* upper, int32_t above, int32_t own_first, int32_t k, int32_t& zero_area) {
    ends.resize(2 * size_t(k));
    end_rank.resize(2 * size_t(k));
    const int32_t* faces = a.faces.data();
    const double* positions = a.positions.data();
    for (int32_t i = 0; i < k; ++i) {
      const int32_t* t = faces + 3 * size_t(i < above ? upper[i] : own_first + (i - above));
      const int c = t[0] == v ? 0 : t[1] == v ? 1 : 2;
      const int32_t p = t[(c + 1) % 3], q = t[(c + 2) % 3];
      if (v < p && v < q) {
        double fn[3];
        cross(positions + 3 * size_t(t[0]), positions + 3 * size_t(t[1]), positions + 3 * size_t(t[2]), fn);
        if (fn[0] == 0.0 && fn[1] == 0.0 && fn[2] == 0.0) ++zero_area;
      }
      ends[2 * size_t(i)] = (uint64_t(uint32_t(p)) << 32) | uint32_t(2 * i);         // side v -> p
      ends[2 * size_t(i) + 1] = (uint64_t(uint32_t(q)) << 32) | uint32_t(2 * i + 1);  // side q -> v
    }
  }

  // The distinct neighbours in increasing order (returns how many), with the arcs entering
  // and leaving each and every arc end's neighbour rank.
  int32_t sort_neighbours(int32_t* neighbours) {
    int32_t d = 0;
    sort_small(ends.data(), ends.data() + ends.size());
    in.clear(), out.clear();
    for (const uint64_t end : ends) {
      const int32_t u = int32_t(end >> 32), tag = int32_t(end & 0xffffffffu);
      if (d == 0 || neighbours[d - 1] != u) {
        neighbours[d++] = u;
        in.push_back(0), out.push_back(0);
      }
      end_rank[tag] = d - 1;
      if (tag & 1) ++in[d - 1];
      else ++out[d - 1];
    }
    return d;
  }

  // Edge (v, u) has in + out triangles; two are consistent when they traverse it in opposite
  // directions (one arc leaves u, one enters it). Each edge is counted at its lower end.
  void count_edges(int32_t v, const int32_t* neighbours, int32_t d, int32_t lower, OneRingCounts& counts,
                   bool& nonmanifold_edge, bool& flipped) {
    int32_t boundary = 0, nonmanifold = 0, inconsistent = 0;
    for (int32_t r = 0; r < d; ++r) {
      const int32_t count = in[r] + out[r];
      const bool bad_direction = count == 2 && !(in[r] == 1 && out[r] == 1);
      nonmanifold_edge |= count > 2;
      flipped |= bad_direction;
      if (r < lower) continue;
      boundary += count == 1;
      nonmanifold += count >= 3;
      inconsistent += bad_direction;
      a.sets.unite(v, neighbours[r]);
    }
    counts.boundary += boundary, counts.nonmanifold_edges += nonmanifold, counts.inconsistent += inconsistent;
  }

  // Fans: with every edge at v on at most two triangles, consistently oriented, the arcs are
  // paths and cycles, and one fan means exactly one of them (then 1, else 2). With flipped
  // edges the fans are the groups of arcs that share a neighbour (their faces share that edge).
  int32_t count_fans(int32_t k, int32_t d, bool flipped) {
    next.assign(d, -1);
    if (!flipped) {
      int32_t start = 0, starts = 0;
      for (int32_t i = 0; i < k; ++i) next[end_rank[2 * i]] = end_rank[2 * i + 1];
      for (int32_t r = 0; r < d; ++r)
        if (in[r] == 0) start = r, ++starts;
      int32_t walked = 0;
      if (starts <= 1)
        for (int32_t x = start; walked <= k;) {
          const int32_t w = next[x];
          if (w < 0) break;  // end of a path
          ++walked;
          if (w == start) break;  // closed the cycle
          x = w;
        }
      return walked == k ? 1 : 2;
    }
    for (int32_t r = 0; r < d; ++r) next[r] = r;  // a union-find over the neighbours
    auto root = [&](int32_t x) {
      while (next[x] != x) x = next[x] = next[next[x]];
      return x;
    };
    int32_t fans = d;
    for (int32_t i = 0; i < k; ++i) {
      const int32_t x = root(end_rank[2 * i]), y = root(end_rank[2 * i + 1]);
      if (x != y) next[std::max(x, y)] = std::min(x, y), --fans;
    }
    return fans;
  }
};

// The neighbours into place: each vertex's list moves from its first face slot (the faces
// before it in vertex_faces(): those above lower vertices and the runs of lower vertices) + its
// id to its offset, in vertex order. Without overflow (every vertex within one neighbour per face plus
// one) that happens within the same buffer, as no list lands on one not moved yet, and then the
// buffer's tail can go; otherwise the lists go to a buffer of their own. `overflow` is sorted.
void compact_neighbours(const Buffer<int32_t>& upper_offsets, const Buffer<int32_t>& lowest_offsets,
                        const Buffer<int32_t>& offsets,
                        const std::vector<std::pair<int32_t, std::vector<int32_t>>>& overflow, Buffer<int32_t>& lists) {
  const int32_t n = int32_t(offsets.size()) - 1;
  Buffer<int32_t> own;
  if (!overflow.empty()) own.resize(offsets[n]);
  int32_t* to = overflow.empty() ? lists.data() : own.data();
  size_t next = 0;  // the next vertex in overflow
  for (int32_t v = 0; v < n; ++v) {
    const int32_t d = offsets[v + 1] - offsets[v];
    const bool over = next < overflow.size() && overflow[next].first == v;
    const int32_t* from = over ? overflow[next++].second.data() : lists.data() + size_t(upper_offsets[v]) + size_t(lowest_offsets[v]) + size_t(v);
    std::copy(from, from + d, to + offsets[v]);
  }
  if (!overflow.empty()) {
    lists.swap(own);
    return;
  }
  lists.resize(offsets[n]);
  release_unused(lists);
}

// Components, numbered in order of their lowest vertex (each set's root; a vertex without
// neighbours in none), and the Euler characteristic V - E + F of each from every vertex's share:
// itself, the edges to its higher neighbours (its sorted row's tail) and the faces it is the
// lowest vertex of (its run). Returns how many. `component` (n entries) holds each vertex's root
// and receives its component in place: a root is its set's lowest id (SharedUnionFind::unite),
// so it is numbered before the vertices that read it.
int32_t number_components(const Buffer<int32_t>& ao, const Buffer<int32_t>& adjacency,
                          const Buffer<int32_t>& lowest_offsets, Buffer<int32_t>& component,
                          Buffer<int64_t>& component_euler) {
  const int32_t n = int32_t(ao.size()) - 1;
  int32_t components = 0;
  for (int32_t v = 0; v < n; ++v) {
    const int32_t root = component[v];
    if (ao[v] == ao[v + 1]) component[v] = -1;
    else component[v] = root == v ? components++ : component[root];
  }
  component_euler.assign(components, 0);
  for (int32_t v = 0; v < n; ++v) {
    if (component[v] < 0) continue;
    const int32_t* row = adjacency.data() + ao[v];
    const int32_t d = ao[v + 1] - ao[v], lower = int32_t(std::lower_bound(row, row + d, v) - row);
    component_euler[component[v]] += 1 - (d - lower) + (lowest_offsets[v + 1] - lowest_offsets[v]);
  }
  return components;
}

// The mean weight over vertices with neighbours, summed in vertex order on one thread: an
// OpenMP reduction adds in an order that depends on the number of threads, and so would
// change the last bits of the result.
double mean_of_weights(const Buffer<int32_t>& offsets, const Buffer<double>& weights) {
  double total = 0.0;
  int64_t counted = 0;
  for (size_t v = 0; v + 1 < offsets.size(); ++v) {
    if (offsets[v] == offsets[v + 1]) continue;
    total += weights[v];
    ++counted;
  }
  return counted ? total / double(counted) : 0.0;
}

}  // namespace

Mesh::Mesh(const std::vector<double>& positions, const int32_t* triangles, int64_t num_triangles,
           const ProgressCallback& progress)
    : Mesh(positions.data(), vertex_count(positions), triangles, num_triangles, progress) {}

Mesh::Mesh(const double* positions, int64_t num_vertices, const int32_t* triangles, int64_t num_triangles,
           const ProgressCallback& progress_callback) {
  Progress progress(progress_callback);  // stages at their share of a large mesh's time; may throw Cancelled
  if (num_vertices > int64_t(INT32_MAX)) throw std::invalid_argument("mesh is too large: more than 2^31 vertices");
  num_vertices_ = static_cast<int32_t>(num_vertices);
  report_.input_vertices = num_vertices_;
  report_.input_triangles = static_cast<int32_t>(num_triangles);
  if (num_vertices_ == 0) throw std::invalid_argument("mesh has no vertices");
  if (num_triangles <= 0) throw std::invalid_argument("mesh has no triangles");
  if (num_triangles > INT32_MAX / 3) throw std::invalid_argument("mesh is too large: more than 2^31 / 3 triangles");
  require_finite_positions(positions, num_vertices_);
  // Minimum and maximum are exact, so the box is the same on any number of threads.
  using Box = std::array<double, 6>;  // lowest x, y, z, highest x, y, z
  const Box box = parallel_reduce(
      0, num_vertices_, kParallelMin, Box{positions[0], positions[1], positions[2], positions[0], positions[1], positions[2]},
      [&](Box& b, int32_t v) {
        const double* p = positions + 3 * size_t(v);
        for (int k = 0; k < 3; ++k) b[k] = std::min(b[k], p[k]), b[k + 3] = std::max(b[k + 3], p[k]);
      },
      [](Box& b, const Box& part) {
        for (int k = 0; k < 3; ++k) b[k] = std::min(b[k], part[k]), b[k + 3] = std::max(b[k + 3], part[k + 3]);
      });
  const double lo[3] = {box[0], box[1], box[2]}, hi[3] = {box[3], box[4], box[5]};
  diagonal_ = std::sqrt((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) +
                        (hi[2] - lo[2]) * (hi[2] - lo[2]));

  // From here every step that takes more than a few tenths of a second on 20M triangles ends
  // with a cancel point (progress.update), so that Esc stops the preparation within a second.
  progress.stage("validate", 0.0, 0.15);
  validate_faces(triangles, num_triangles);
  progress.stage("order", 0.15, 0.45);
  reorder_for_locality(positions, triangles, lo, hi, progress);
  progress.update(1.0);
  build_adjacency(progress);
  release_freed_heap(4 * size_t(num_vertices_));
}

void Mesh::validate_faces(const int32_t* triangles, int64_t num_triangles) {
  // One pass for both checks. An out-of-range index is an error, not something to repair (the
  // shared check names the row); a repeated vertex drops the triangle.
  const int64_t m = num_triangles;
  const uint32_t n = uint32_t(num_vertices_);
  struct Counts {
    int out_of_range = 0, degenerate = 0;
  };
  const Counts counts = parallel_reduce(
      0, m, kParallelMin, Counts{},
      [&](Counts& c, int64_t f) {
        const int32_t* t = triangles + 3 * f;
        c.out_of_range |= (uint32_t(t[0]) >= n) | (uint32_t(t[1]) >= n) | (uint32_t(t[2]) >= n);
        c.degenerate += (t[0] == t[1]) | (t[1] == t[2]) | (t[2] == t[0]);
      },
      [](Counts& c, const Counts& part) { c.out_of_range |= part.out_of_range, c.degenerate += part.degenerate; });
  const int out_of_range = counts.out_of_range, degenerate = counts.degenerate;
  if (out_of_range) require_indices_in_range(triangles, num_triangles, 3, num_vertices_, "triangle");
  report_.degenerate_triangles = degenerate;
  // The candidates, in input order; duplicates among them go once the vertices are renumbered.
  face_source_.resize(m - degenerate);
  if (degenerate == 0) {
    parallel_for(0, m, kParallelMin, [&](int64_t f) { face_source_[f] = int32_t(f); });
  } else {
    int64_t j = 0;
    for (int64_t f = 0; f < m; ++f) {
      const int32_t* t = triangles + 3 * f;
      if (t[0] == t[1] || t[1] == t[2] || t[2] == t[0]) {
        report_.dropped_triangles.push_back(static_cast<int32_t>(f));
        dropped_rows_.insert(dropped_rows_.end(), t, t + 3);
      } else {
        face_source_[j++] = int32_t(f);
      }
    }
  }
  if (face_source_.empty())
    throw std::invalid_argument("mesh has no valid triangles: all " + std::to_string(num_triangles) +
                                " repeat a vertex or duplicate another");
}

namespace {
// Spreads the low 21 bits of x so that they occupy every third bit.
uint64_t spread_bits(uint64_t x) {
  x &= 0x1fffff;
  x = (x | x << 32) & 0x1f00000000ffffull;
  x = (x | x << 16) & 0x1f0000ff0000ffull;
  x = (x | x << 8) & 0x100f00f00f00f00full;
  x = (x | x << 4) & 0x10c30c30c30c30c3ull;
  x = (x | x << 2) & 0x1249249249249249ull;
  return x;
}
}  // namespace

void Mesh::reorder_for_locality(const double* positions, const int32_t* triangles, const double* lo,
                                 const double* hi, Progress& progress) {
  const int32_t n = num_vertices_;
  const double extent = std::max({hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2], 1e-300});
  auto key_of = [&](int32_t v) {
    uint64_t k = 0;
    for (int axis = 0; axis < 3; ++axis) {
      // Differences near the double range overflow to inf and inf / inf is NaN, which
      // std::min passes through: NaN goes to 0 (converting it to an integer is undefined).
      const double t = (positions[3 * size_t(v) + axis] - lo[axis]) / extent;
      const double unit = t >= 0.0 ? std::min(t, 1.0) : 0.0;
      k |= spread_bits(uint64_t(unit * 2097151.0)) << axis;
    }
    return k;
  };
  // Vertices by key, ties by vertex.
  Buffer<uint64_t> sorted;
  sort_ids_by_key(n, key_of, sorted, [&](double done) { progress.update(0.05 + 0.45 * done); });
  const uint64_t id_mask = (uint64_t(1) << id_bits_for(n)) - 1;
  vertex_source_.resize(n);
  parallel_for(0, n, kParallelMin, [&](int32_t i) { vertex_source_[i] = int32_t(sorted[i] & id_mask); });
  Buffer<uint64_t>().swap(sorted);
  vertex_index_.resize(n);
  positions_.resize(3 * size_t(n));
  parallel_for(0, n, kParallelMin, [&](int32_t i) {
    const int32_t old = vertex_source_[i];
    vertex_index_[old] = i;
    for (int k = 0; k < 3; ++k) positions_[3 * size_t(i) + k] = positions[3 * size_t(old) + k];
  });
  progress.update(0.55);
  // The candidate faces in the new numbering, in order of their lowest vertex, ties in input
  // order. A counting sort with a bucket per vertex scatters every face to a random place;
  // instead the keys (lowest vertex, candidate) are radix-sorted in
  // two passes of about ten bits, whose scatters stay within a few thousand cache lines, and the
  // faces are then gathered in order. They are renumbered while the keys are made, reading the
  // caller's rows in order: gathering renumbered rows reads one array in the new order instead
  // of a caller's row and three of vertex_index_'s entries (the gather was a fifth of the
  // preparation).
  const int32_t m = static_cast<int32_t>(face_source_.size());
  Buffer<uint64_t> keyed(m);
  Buffer<int32_t> renumbered(3 * size_t(m));
  parallel_for(0, m, kParallelMin, [&](int32_t i) {
    const int32_t* t = &triangles[3 * size_t(face_source_[i])];
    int32_t* r = &renumbered[3 * size_t(i)];
    for (int c = 0; c < 3; ++c) r[c] = vertex_index_[t[c]];
    keyed[i] = (uint64_t(uint32_t(std::min({r[0], r[1], r[2]}))) << 32) | uint32_t(i);
  });
  Buffer<int32_t>().swap(vertex_index_);  // 2 bytes a triangle, made again on first use
  progress.update(0.65);
  {
    int bits = 1;
    while (bits < 31 && (int64_t(1) << bits) < int64_t(n)) ++bits;
    const int passes = (bits + 10) / 11, digit = (bits + passes - 1) / passes;
    const uint64_t mask = (uint64_t(1) << digit) - 1;
    Buffer<uint64_t> other(m);
    Buffer<int32_t> ignored;
    for (int pass = 0; pass < passes; ++pass) {
      const int shift = 32 + pass * digit;
      const uint64_t* from = keyed.data();
      stable_counting_sort(
          m, int32_t(mask + 1), [&](int64_t i) { return int32_t((from[i] >> shift) & mask); },
          [&](int64_t i, int32_t at) { other[at] = from[i]; }, ignored);
      keyed.swap(other);
      progress.update(0.65 + 0.2 * (pass + 1) / passes);
    }
  }
  faces_.resize(3 * size_t(m));
  Buffer<int32_t> source(m);
  lowest_offsets_.resize(size_t(n) + 1);
  // In slices of the sorted keys, whose read pages go back after each (all but the last key,
  // which the next slice reads): the keys (8 bytes a triangle) shrink as the faces and their
  // sources (16) grow, instead of all being held at the end, which was the preparation's peak.
  constexpr int32_t kSlices = 8;
  for (int32_t slice = 0; slice < kSlices; ++slice) {
    const int32_t begin = int32_t(int64_t(m) * slice / kSlices), end = int32_t(int64_t(m) * (slice + 1) / kSlices);
    parallel_for(begin, end, kParallelMin, [&](int32_t j) {
      // The rows are read in a new order: fetch a few faces ahead.
      if (j + 8 < m) prefetch(&renumbered[3 * size_t(keyed[j + 8] & 0xffffffffu)]);
      const int64_t i = int64_t(keyed[j] & 0xffffffffu);
      for (int c = 0; c < 3; ++c) faces_[3 * size_t(j) + c] = renumbered[3 * size_t(i) + c];
      source[j] = face_source_[i];
      // The runs of each lowest vertex: every vertex after the previous face's lowest, up to
      // this face's, starts here.
      const int64_t lowest = int64_t(keyed[j] >> 32), previous = j ? int64_t(keyed[j - 1] >> 32) : -1;
      for (int64_t v = previous + 1; v <= lowest; ++v) lowest_offsets_[v] = j;
    });
    if (end > begin) release_range(keyed, size_t(begin), size_t(end) - 1);
  }
  for (int64_t v = int64_t(keyed[m - 1] >> 32) + 1; v <= int64_t(n); ++v) lowest_offsets_[v] = m;
  Buffer<int32_t>().swap(renumbered);
  face_source_.swap(source);
  progress.update(0.95);
  drop_duplicate_faces();
}

void Mesh::drop_duplicate_faces() {
  const Buffer<int32_t>& lowest_offsets = lowest_offsets_;
  // Duplicates (the same three vertices, either orientation) share their lowest vertex, so they
  // sit in one run of the sorted faces, which holds them in input order: the first is kept.
  const int32_t n = num_vertices_;
  const int32_t m = num_faces();
  std::vector<uint8_t> duplicate(m, 0);
  int32_t duplicates = 0;
  parallel_region(team_for(n, kParallelMin), [&](Team& team) {
    std::vector<std::pair<uint64_t, int32_t>> run;  // (other two vertices, face), long runs only
    int32_t found = 0;                              // this thread's duplicates
    team.for_static(0, n, [&](int32_t v) {
      const int32_t b = lowest_offsets[v], e = lowest_offsets[v + 1];
      if (e - b < 2) return;
      auto others = [&](int32_t f) {
        const int32_t* t = &faces_[3 * size_t(f)];
        const int32_t x = t[0] == v ? t[1] : t[0], y = t[2] == v ? t[1] : t[2];
        return (uint64_t(uint32_t(std::min(x, y))) << 32) | uint32_t(std::max(x, y));
      };
      if (e - b <= 16) {
        for (int32_t i = b; i < e; ++i) {
          if (duplicate[i]) continue;
          const uint64_t key = others(i);
          for (int32_t j = i + 1; j < e; ++j)
            if (!duplicate[j] && others(j) == key) duplicate[j] = 1, ++found;
        }
      } else {  // a fan around a low vertex: sort instead of comparing every pair
        run.clear();
        for (int32_t i = b; i < e; ++i) run.push_back({others(i), i});
        std::sort(run.begin(), run.end());
        for (size_t i = 1; i < run.size(); ++i)
          if (run[i].first == run[i - 1].first) duplicate[run[i].second] = 1, ++found;
      }
    });
    team.critical([&] { duplicates += found; });
  });
  if (duplicates == 0) return;
  report_.duplicate_triangles = duplicates;
  // Dropped triangles (the repeated-vertex ones are there already) in input order, with rows.
  std::vector<std::pair<int32_t, std::array<int32_t, 3>>> dropped;
  for (size_t i = 0; i < report_.dropped_triangles.size(); ++i)
    dropped.push_back({report_.dropped_triangles[i], {dropped_rows_[3 * i], dropped_rows_[3 * i + 1], dropped_rows_[3 * i + 2]}});
  int32_t kept = 0;
  for (int32_t f = 0; f < m; ++f) {
    const int32_t* t = &faces_[3 * size_t(f)];
    if (duplicate[f]) {
      dropped.push_back({face_source_[f], {vertex_source_[t[0]], vertex_source_[t[1]], vertex_source_[t[2]]}});
      continue;
    }
    for (int c = 0; c < 3; ++c) faces_[3 * size_t(kept) + c] = t[c];
    face_source_[kept++] = face_source_[f];
  }
  faces_.resize(3 * size_t(kept));
  face_source_.resize(kept);
  find_lowest_offsets();
  std::sort(dropped.begin(), dropped.end());
  report_.dropped_triangles.clear();
  dropped_rows_.clear();
  for (const auto& [index, row] : dropped) {
    report_.dropped_triangles.push_back(index);
    dropped_rows_.insert(dropped_rows_.end(), row.begin(), row.end());
  }
}

std::vector<int32_t> Mesh::caller_triangles() const {
  std::vector<int32_t> out(3 * size_t(report_.input_triangles));
  const int32_t m = num_faces();
  parallel_for(0, m, kParallelMin, [&](int32_t f) {
    for (int c = 0; c < 3; ++c) out[3 * size_t(face_source_[f]) + c] = vertex_source_[faces_[3 * size_t(f) + c]];
  });
  for (size_t i = 0; i < report_.dropped_triangles.size(); ++i)
    for (int c = 0; c < 3; ++c) out[3 * size_t(report_.dropped_triangles[i]) + c] = dropped_rows_[3 * i + c];
  return out;
}

int32_t Mesh::first_corner(int32_t v) const {
  const int32_t f = first_face(v);
  if (f < 0) return -1;
  const int32_t* t = &faces_[3 * size_t(f)];
  return 3 * face_source_[f] + (t[0] == v ? 0 : t[1] == v ? 1 : 2);
}

int32_t Mesh::first_face(int32_t v) const {
  int32_t first = -1;
  walk_faces(v, [&](int32_t f) { return first = f, true; });
  return first;
}

int32_t Mesh::face_count(int32_t v) const {
  int32_t count = 0;
  for_each_face(v, [&](int32_t) { ++count; });
  return count;
}

bool Mesh::loose_face(int32_t f) const {
  const int32_t* t = &faces_[3 * size_t(f)];
  return face_count(t[0]) == 1 && face_count(t[1]) == 1 && face_count(t[2]) == 1;
}

// After duplicates are dropped: the faces stay in order of their lowest vertex.
void Mesh::find_lowest_offsets() {
  const int32_t m = num_faces();
  int32_t v = 0;
  for (int32_t f = 0; f < m; ++f) {
    const int32_t* t = &faces_[3 * size_t(f)];
    const int32_t lowest = std::min({t[0], t[1], t[2]});
    while (v <= lowest) lowest_offsets_[v++] = f;
  }
  while (v <= num_vertices_) lowest_offsets_[v++] = m;
}

void Mesh::fill_vertex_faces() const {
  // Each vertex's faces in increasing order: a stable counting sort of the corners.
  vertex_faces_.resize(faces_.size());
  stable_counting_sort(
      int64_t(faces_.size()), num_vertices_, [&](int64_t c) { return faces_[c]; },
      [&](int64_t c, int32_t at) { vertex_faces_[at] = int32_t(c / 3); }, vertex_face_offsets_);
}

void Mesh::build_vertex_faces() const {
  std::call_once(vertex_faces_once_, [this] {
    fill_vertex_faces();
    vertex_faces_built_.store(true, std::memory_order_release);
  });
}

// A vertex's walk reads the runs of its lower neighbours: a vertex of high valence below its
// neighbours (a fan's centre, a cone's apex) makes each of them read its whole run. Where the
// walks would read more than kWalkPerFace faces a face, the table is made now and kept.
void Mesh::keep_vertex_faces_where_walks_cost() {
  const int64_t reads = parallel_count<int64_t>(0, num_vertices_, kParallelMin, [&](int32_t v) {
    int64_t sum = 0;
    for (int32_t i = adjacency_offsets_[v]; i < adjacency_offsets_[v + 1] && adjacency_[i] < v; ++i)
      sum += lowest_offsets_[adjacency_[i] + 1] - lowest_offsets_[adjacency_[i]];
    return sum;
  });
  if (reads > kWalkPerFace * int64_t(num_faces())) build_vertex_faces();
}

void Mesh::build_adjacency(Progress& progress) {
  progress.stage("adjacency", 0.45, 0.8);
  const int32_t n = num_vertices_;
  // Each vertex's faces it is not the lowest vertex of, in increasing order (a stable counting
  // sort of the two other corners of each face): with the faces' runs, its faces, in 10 bytes a
  // triangle where a table of them (vertex_faces()) is 14.
  // The two other corners of each face are listed first (the sort reads each twice; this is
  // below the pass's peak).
  Buffer<int32_t> upper, upper_offsets, others(2 * size_t(num_faces()));
  parallel_for(0, num_faces(), kParallelMin, [&](int32_t f) {
    const int32_t* t = &faces_[3 * size_t(f)];
    const int lowest = (t[0] < t[1] && t[0] < t[2]) ? 0 : (t[1] < t[2] ? 1 : 2);
    others[2 * size_t(f)] = t[lowest == 2 ? 0 : lowest + 1];
    others[2 * size_t(f) + 1] = t[lowest == 0 ? 2 : lowest - 1];
  });
  upper.resize(others.size());
  stable_counting_sort(
      int64_t(others.size()), n, [&](int64_t i) { return others[i]; },
      [&](int64_t i, int32_t at) { upper[at] = int32_t(i >> 1); }, upper_offsets);
  Buffer<int32_t>().swap(others);
  report_.isolated_vertices = parallel_count<int32_t>(0, n, kParallelMin, [&](int32_t v) {
    return upper_offsets[v] == upper_offsets[v + 1] && lowest_offsets_[v] == lowest_offsets_[v + 1];
  });
  // First pass, per vertex, from its faces alone (OneRingScan). Neighbours wait in `scratch`
  // (at the vertex's first face slot + its id; a non-manifold vertex's extra ones in `overflow`)
  // until the offsets are known: half the memory of slots for two neighbours per face, which
  // was the preparation's peak. Edge ids and tables come later, on demand (build_edges).
  // Buffers are written on the threads that fill them (see core/buffer.hpp): every entry a loop
  // skips is set explicitly.
  Buffer<int32_t> scratch(faces_.size() + size_t(n));
  Buffer<int32_t> degree(n + 1);
  degree[n] = 0;
  Buffer<uint8_t> manifold(n);
  SharedUnionFind sets(n);
  const OneRingArrays arrays{faces_, upper, upper_offsets, lowest_offsets_, positions_, scratch, degree,
                             manifold, sets};
  int32_t boundary = 0, nonmanifold_edges = 0, inconsistent = 0, pinched = 0, zero_area = 0;
  std::vector<std::pair<int32_t, std::vector<int32_t>>> overflow;
  // In slices of the vertices with a cancel point after each (the pass is seconds on 20M
  // triangles); each vertex's scan is its own, so the slicing changes nothing.
  constexpr int32_t kSlices = 8;
  for (int32_t slice = 0; slice < kSlices; ++slice) {
    const int32_t begin = int32_t(int64_t(n) * slice / kSlices), end = int32_t(int64_t(n) * (slice + 1) / kSlices);
    parallel_region(team_for(end - begin, kParallelMin), [&](Team& team) {
      OneRingScan scan(arrays);
      OneRingCounts mine;
      team.for_static(begin, end, [&](int32_t v) { scan.scan(v, mine); });
      team.critical([&] {
        boundary += mine.boundary, nonmanifold_edges += mine.nonmanifold_edges, inconsistent += mine.inconsistent;
        pinched += mine.pinched, zero_area += mine.zero_area;
        for (auto& entry : scan.overflow) overflow.push_back(std::move(entry));
      });
    });
    // The slice's lists of faces above its vertices are read: their pages go back, so that the
    // pass holds those lists and the neighbour buffer's written slots about one at a time.
    release_range(upper, size_t(upper_offsets[begin]), size_t(upper_offsets[end]));
    progress.update(0.8 * (slice + 1) / kSlices);
  }
  report_.boundary_edges = boundary;
  report_.nonmanifold_edges = nonmanifold_edges;
  report_.inconsistent_edges = inconsistent;
  report_.nonmanifold_vertices = pinched;
  manifold_vertex_.assign(std::move(manifold));  // nothing kept when every vertex is manifold
  report_.zero_area_triangles = zero_area;

  adjacency_offsets_.swap(degree);
  exclusive_scan(adjacency_offsets_);
  std::sort(overflow.begin(), overflow.end());
  compact_neighbours(upper_offsets, lowest_offsets_, adjacency_offsets_, overflow, scratch);
  decltype(overflow)().swap(overflow);
  adjacency_.swap(scratch);
  // From here a vertex's faces are walked from the adjacency and the faces' runs (for_each_face).
  Buffer<int32_t>().swap(upper);
  Buffer<int32_t>().swap(upper_offsets);
  // Each edge at its lower end: the tail of that end's sorted row.
  const int64_t edges = parallel_count<int64_t>(0, n, kParallelMin, [&](int32_t v) {
    const int32_t *row = adjacency_.data() + adjacency_offsets_[v], *end = adjacency_.data() + adjacency_offsets_[v + 1];
    return int64_t(end - std::upper_bound(row, end, v));
  });
  if (edges > INT32_MAX) throw std::invalid_argument("mesh is too large: more than 2^31 edges");
  num_edges_ = int32_t(edges);
  // Each vertex's root: the sets go before the weights are made.
  Buffer<int32_t> component(n);
  parallel_for(0, n, kParallelMin, [&](int32_t v) { component[v] = sets.find(v); });
  std::vector<int32_t>().swap(sets.parents());
  release_freed_heap(4 * size_t(n));
  keep_vertex_faces_where_walks_cost();

  progress.stage("normals and weights", 0.8, 0.92);
  weigh();
  progress.stage("components", 0.92, 1.0);
  report_.components = number_components(adjacency_offsets_, adjacency_, lowest_offsets_, component, component_euler_);
  component_.assign(component, report_.components);
  mean_weight_ = mean_of_weights(adjacency_offsets_, weights_);
}

// Area-weighted: the unnormalised face normals (twice the areas) summed at each vertex, in the
// order of its faces, then normalised.
void Mesh::normal_at(int32_t v, double* out) const {
  double sum[3] = {0, 0, 0};
  for_each_face(v, [&](int32_t f) {
    const int32_t* t = &faces_[3 * size_t(f)];
    double fn[3];
    cross(position(t[0]), position(t[1]), position(t[2]), fn);
    sum[0] += fn[0];
    sum[1] += fn[1];
    sum[2] += fn[2];
  });
  unit_normal(sum, out);
}

// normal_at's sums for a range of vertices, the same faces added in the same order
// (for_block_faces): each face's cross product made once for its corners in the range instead of
// once per corner.
void Mesh::normal_sums(int32_t a, int32_t b, std::vector<double>& sums) const {
  sums.assign(3 * size_t(b - a), 0.0);
  auto add = [&](const double* fn, int32_t v) {
    double* sum = &sums[3 * size_t(v - a)];
    sum[0] += fn[0];
    sum[1] += fn[1];
    sum[2] += fn[2];
  };
  auto face_normal = [&](int32_t f, double* fn) {
    const int32_t* t = &faces_[3 * size_t(f)];
    cross(position(t[0]), position(t[1]), position(t[2]), fn);
    return t;
  };
  for_block_faces(
      a, b,
      [&](int32_t f, int32_t v) {
        double fn[3];
        face_normal(f, fn);
        add(fn, v);
      },
      [&](int32_t f) {
        double fn[3];
        const int32_t* t = face_normal(f, fn);
        for (int c = 0; c < 3; ++c)
          if (t[c] < b) add(fn, t[c]);
      });
}

void Mesh::fill_normals() const {
  const int32_t n = num_vertices_;
  normals_.resize(3 * size_t(n));
  parallel_for(0, n, kParallelMin, [&](int32_t v) { normal_at(v, &normals_[3 * size_t(v)]); });
}

// The importance weight of thesis eq. 4.1 from the neighbours' normals, without a normal per
// vertex (24 bytes a vertex, which made this step the preparation's peak): vertices are weighed a
// block at a time with the normals of the block and of one block on either side in a ring (ids
// follow a space-filling curve, so nearly every neighbour is there); a neighbour outside has its
// normal computed where read, to the same bits.
void Mesh::weigh() {
  constexpr int32_t kBlock = 1 << 14;
  const int32_t n = num_vertices_;
  const int64_t span = 3 * int64_t(kBlock);  // the ring holds ids [b - kBlock, b + 2 kBlock)
  std::vector<double> ring(3 * size_t(std::min<int64_t>(span, n)));
  auto slot = [&](int32_t v) { return &ring[3 * size_t(v % span)]; };
  auto compute = [&](int32_t from, int32_t to) {  // in chunks of vertices, each on one thread
    constexpr int32_t kChunk = 1024;
    parallel_region(team_for(to - from, kParallelMinCostly), [&](Team& team) {
      std::vector<double> sums;
      team.for_static(0, (to - from + kChunk - 1) / kChunk, [&](int32_t chunk) {
        const int32_t a = from + chunk * kChunk, e = std::min(to, a + kChunk);
        normal_sums(a, e, sums);
        for (int32_t v = a; v < e; ++v) unit_normal(&sums[3 * size_t(v - a)], slot(v));
      });
    });
  };
  // Vertices of many neighbours (a fan's centre) are read from outside the ring by each of
  // them: their normals are made once, with normal_at as everywhere else.
  constexpr int32_t kHubDegree = 64;
  auto degree = [&](int32_t v) { return adjacency_offsets_[v + 1] - adjacency_offsets_[v]; };
  std::vector<int32_t> hubs;
  for (int32_t v = 0; v < n; ++v)
    if (degree(v) > kHubDegree) hubs.push_back(v);
  std::vector<double> hub_normals(3 * hubs.size());
  parallel_for(0, int32_t(hubs.size()), 1, [&](int32_t i) { normal_at(hubs[i], &hub_normals[3 * size_t(i)]); });
  auto far_normal = [&](int32_t u, double* out) -> const double* {
    if (degree(u) <= kHubDegree) return normal_at(u, out), out;
    return &hub_normals[3 * size_t(std::lower_bound(hubs.begin(), hubs.end(), u) - hubs.begin())];
  };
  weights_.resize(n);
  compute(0, int32_t(std::min<int64_t>(n, 2 * int64_t(kBlock))));
  for (int32_t b = 0; b < n; b += kBlock) {
    const int32_t end = int32_t(std::min<int64_t>(n, int64_t(b) + kBlock));
    const int64_t low = int64_t(b) - kBlock, high = std::min<int64_t>(n, int64_t(b) + 2 * kBlock);
    if (b > 0 && high > int64_t(b) + kBlock) compute(b + kBlock, int32_t(high));  // the block after this one
    parallel_for(b, end, kParallelMinCostly, [&](int32_t v) {
      const int32_t d = adjacency_offsets_[v + 1] - adjacency_offsets_[v];
      if (d == 0) {
        weights_[v] = 0.0;
        return;
      }
      const int32_t* neighbours = adjacency_.data() + adjacency_offsets_[v];
      // Thesis eq. 4.1: x(v) = (|N_v| - sum_u n_v . n_u) / (2 |N_v|), the one-ring normal deviation.
      const double* nv = slot(v);
      double dots = 0.0, far[3];
      for (int32_t r = 0; r < d; ++r) {
        const int32_t u = neighbours[r];
        const double* nu = u >= low && u < high ? slot(u) : far_normal(u, far);
        dots += nv[0] * nu[0] + nv[1] * nu[1] + nv[2] * nu[2];
      }
      weights_[v] = std::clamp((double(d) - dots) / (2.0 * double(d)), 0.0, 1.0);
    });
  }
}

void Mesh::build_vertex_index() const {
  std::call_once(vertex_index_once_, [this] {
    vertex_index_.resize(size_t(num_vertices_));
    parallel_for(0, num_vertices_, kParallelMin, [&](int32_t i) { vertex_index_[vertex_source_[i]] = i; });
    vertex_index_built_.store(true, std::memory_order_release);
  });
}

std::vector<int32_t> Mesh::internal_ids(const std::vector<int32_t>& caller_ids) const {
  const int32_t n = num_vertices_;
  for (int32_t c : caller_ids)
    if (c < 0 || c >= n) throw std::out_of_range("vertex " + std::to_string(c) + " is not one of the mesh's");
  std::vector<int32_t> out(caller_ids.size(), -1);
  if (vertex_index_built_.load(std::memory_order_acquire)) {
    for (size_t i = 0; i < out.size(); ++i) out[i] = vertex_index_[caller_ids[i]];
    return out;
  }
  if (2 * caller_ids.size() >= size_t(n)) {
    // Half the vertices or more (a result that keeps most of its input): the inverse of
    // vertex_source takes no more memory than the sorted list below, and no searches.
    std::vector<int32_t> inverse(n);
    parallel_for(0, n, kParallelMin, [&](int32_t v) { inverse[vertex_source_[v]] = v; });
    parallel_for(int64_t(0), int64_t(out.size()), kParallelMin, [&](int64_t i) { out[i] = inverse[caller_ids[i]]; });
    return out;
  }
  std::vector<std::pair<int32_t, int32_t>> wanted(caller_ids.size());  // (caller id, position)
  for (size_t i = 0; i < wanted.size(); ++i) wanted[i] = {caller_ids[i], int32_t(i)};
  std::sort(wanted.begin(), wanted.end());
  std::vector<uint64_t> bits((size_t(n) + 63) / 64, 0);
  for (const auto& entry : wanted) bits[size_t(entry.first) >> 6] |= uint64_t(1) << (entry.first & 63);
  parallel_for(0, n, kParallelMin, [&](int32_t v) {
    const int32_t c = vertex_source_[v];
    if (!((bits[size_t(c) >> 6] >> (c & 63)) & 1)) return;
    auto it = std::lower_bound(wanted.begin(), wanted.end(), std::make_pair(c, INT32_MIN));
    for (; it != wanted.end() && it->first == c; ++it) out[size_t(it->second)] = v;  // one v per caller id
  });
  return out;
}

void Mesh::build_normals() const {
  std::call_once(normals_once_, [this] {
    fill_normals();
    normals_built_.store(true, std::memory_order_release);
  });
}

// Apart from the one-ring pass: three square roots and divisions per face were a sixth of that
// pass, for a value only area-weighted sampling reads.
void Mesh::build_vertex_areas() const {
  std::call_once(areas_once_, [this] {
    const int32_t n = num_vertices_;
    vertex_areas_.resize(n);
    parallel_for(0, n, kParallelMin, [&](int32_t v) {
      double area = 0.0;
      for_each_face(v, [&](int32_t f) {
        const int32_t* t = &faces_[3 * size_t(f)];
        double fn[3];
        cross(position(t[0]), position(t[1]), position(t[2]), fn);
        area += std::sqrt(fn[0] * fn[0] + fn[1] * fn[1] + fn[2] * fn[2]) / 6.0;  // a third of half the cross
      });
      vertex_areas_[v] = area;
    });
    // Summed in vertex order on one thread, as the mean weight.
    double total = 0.0;
    int64_t counted = 0;
    for (int32_t v = 0; v < n; ++v) {
      total += vertex_areas_[v];
      if (adjacency_offsets_[v] == adjacency_offsets_[v + 1]) continue;
      ++counted;
    }
    mean_vertex_area_ = counted ? total / double(counted) : 0.0;
    areas_built_.store(true, std::memory_order_release);
  });
}

void Mesh::edge_numbering(Buffer<int32_t>& lower, Buffer<int32_t>& edge_base) const {
  const int32_t n = num_vertices_;
  const auto& ao = adjacency_offsets_;
  lower.resize(n);
  edge_base.resize(size_t(n) + 1);
  edge_base[n] = 0;
  parallel_for(0, n, kParallelMin, [&](int32_t v) {
    const int32_t* row = adjacency_.data() + ao[v];
    const int32_t d = ao[v + 1] - ao[v];
    lower[v] = int32_t(std::lower_bound(row, row + d, v) - row);
    edge_base[v] = d - lower[v];  // (each edge belongs to its lower end)
  });
  exclusive_scan(edge_base);
}

void Mesh::build_edges() const {
  std::call_once(edges_once_, [this] {
    const int32_t n = num_vertices_;
    const auto& ao = adjacency_offsets_;
    Buffer<int32_t> lower, edge_base;
    edge_numbering(lower, edge_base);
    adjacency_edge_.resize(ao[n]);
    edge_vertices_.resize(2 * size_t(num_edges_));
    edge_face_offsets_.resize(size_t(num_edges_) + 1);
    edge_face_offsets_[num_edges_] = 0;
    // Each vertex writes its own edges: their slots in both rows, their ends and how many faces
    // each has (summed into offsets after).
    parallel_region(team_for(n, kParallelMin), [&](Team& team) {
      team.for_static(0, n, [&](int32_t v) {
        const int32_t* row = adjacency_.data() + ao[v];
        const int32_t d = ao[v + 1] - ao[v], low = lower[v];
        for (int32_t r = low; r < d; ++r) {
          const int32_t u = row[r], e = edge_base[v] + (r - low);
          adjacency_edge_[ao[v] + r] = e;
          edge_vertices_[2 * size_t(e)] = v;
          edge_vertices_[2 * size_t(e) + 1] = u;
          edge_face_offsets_[e] = 0;
          // The same edge in u's row, among u's lower neighbours (sorted, and v is one of them).
          const int32_t* u_row = adjacency_.data() + ao[u];
          adjacency_edge_[ao[u] + int32_t(std::lower_bound(u_row, u_row + lower[u], v) - u_row)] = e;
        }
        for_each_face(v, [&](int32_t f) {
          const int32_t* t = &faces_[3 * size_t(f)];
          const int c = t[0] == v ? 0 : t[1] == v ? 1 : 2;
          for (int32_t u : {t[(c + 1) % 3], t[(c + 2) % 3]})
            if (u > v) ++edge_face_offsets_[edge_base[v] + int32_t(std::lower_bound(row + low, row + d, u) - (row + low))];
        });
      });
    });
    exclusive_scan(edge_face_offsets_);
    edges_built_.store(true, std::memory_order_release);
  });
}

void Mesh::build_edge_faces() const {
  ensure_edges();
  std::call_once(edge_faces_once_, [this] {
    const int32_t n = num_vertices_;
    const auto& ao = adjacency_offsets_;
    Buffer<int32_t> lower, edge_base;
    edge_numbering(lower, edge_base);
    edge_faces_.resize(faces_.size());
    face_edges_.resize(faces_.size());
    // Each vertex writes the edge of each face side it owns and its edges' faces, in
    // increasing order.
    parallel_region(team_for(n, kParallelMin), [&](Team& team) {
      std::vector<int32_t> fill;
      team.for_static(0, n, [&](int32_t v) {
        const int32_t* row = adjacency_.data() + ao[v];
        const int32_t d = ao[v + 1] - ao[v], low = lower[v];
        fill.assign(edge_face_offsets_.data() + edge_base[v], edge_face_offsets_.data() + edge_base[v + 1]);
        for_each_face(v, [&](int32_t f) {
          const int32_t* t = &faces_[3 * size_t(f)];
          const int c = t[0] == v ? 0 : t[1] == v ? 1 : 2;
          for (int side : {c, (c + 2) % 3}) {
            const int32_t u = t[side == c ? (c + 1) % 3 : side];
            if (u < v) continue;  // the edge belongs to the other end
            const int32_t j = int32_t(std::lower_bound(row + low, row + d, u) - (row + low));
            face_edges_[3 * size_t(f) + side] = edge_base[v] + j;
            edge_faces_[fill[j]++] = f;
          }
        });
      });
    });
    edge_faces_built_.store(true, std::memory_order_release);
  });
}

int32_t Mesh::find_edge(int32_t a, int32_t b) const {
  if (a < 0 || a >= num_vertices_ || b < 0 || b >= num_vertices_) return -1;
  ensure_edges();
  const auto* begin = adjacency_.data() + adjacency_offsets_[a];
  const auto* end = adjacency_.data() + adjacency_offsets_[a + 1];
  const auto* it = std::lower_bound(begin, end, b);
  return (it != end && *it == b) ? adjacency_edge_[it - adjacency_.data()] : -1;
}

}  // namespace topstoc
