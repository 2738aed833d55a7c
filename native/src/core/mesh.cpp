#include "topstoc/core/mesh.hpp"
#include "topstoc/core/parallel.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <numeric>
#include <stdexcept>
#include <utility>

#include "core/fans.hpp"
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

// Exclusive prefix sum in place over counts[0..n), with counts[n] receiving the total.
void exclusive_scan(std::vector<int32_t>& counts) {
  int64_t sum = 0;
  for (auto& c : counts) {
    const int64_t x = c;
    c = static_cast<int32_t>(sum);
    sum += x;
  }
  if (sum > INT32_MAX) throw std::invalid_argument("mesh is too large: more than 2^31 incidences");
}

}  // namespace

Mesh::Mesh(std::vector<double> positions, const int32_t* triangles, int64_t num_triangles,
           const ProgressCallback& progress_callback)
    : positions_(std::move(positions)) {
  Progress progress(progress_callback);  // steps at their share of the time on the horse; may throw Cancelled
  if (positions_.size() % 3 != 0) throw std::invalid_argument("positions must hold 3 coordinates per vertex");
  if (positions_.size() / 3 > size_t(INT32_MAX))
    throw std::invalid_argument("mesh is too large: more than 2^31 vertices");
  num_vertices_ = static_cast<int32_t>(positions_.size() / 3);
  report_.input_vertices = num_vertices_;
  report_.input_triangles = static_cast<int32_t>(num_triangles);
  if (num_vertices_ == 0) throw std::invalid_argument("mesh has no vertices");
  if (num_triangles <= 0) throw std::invalid_argument("mesh has no triangles");
  if (num_triangles > INT32_MAX / 3) throw std::invalid_argument("mesh is too large: more than 2^31 / 3 triangles");
  require_finite_positions(positions_.data(), num_vertices_);
  double lo[3] = {positions_[0], positions_[1], positions_[2]}, hi[3] = {lo[0], lo[1], lo[2]};
  for (int32_t v = 0; v < num_vertices_; ++v)
    for (int k = 0; k < 3; ++k) {
      lo[k] = std::min(lo[k], positions_[3 * size_t(v) + k]);
      hi[k] = std::max(hi[k], positions_[3 * size_t(v) + k]);
    }
  diagonal_ = std::sqrt((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) +
                        (hi[2] - lo[2]) * (hi[2] - lo[2]));

  progress.stage("validate", 0.0, 0.2);
  validate_and_copy_faces(triangles, num_triangles);
  progress.stage("order", 0.2, 0.4);
  reorder_for_locality(lo, hi);
  progress.stage("adjacency", 0.4, 0.72);
  build_vertex_faces();
  build_adjacency_and_edges();
  build_edge_faces();
  progress.stage("normals and weights", 0.72, 0.82);
  compute_normals_and_weights();
  progress.stage("components", 0.82, 1.0);
  compute_components_and_manifoldness();
}

void Mesh::validate_and_copy_faces(const int32_t* triangles, int64_t num_triangles) {
  // Range check first: an out-of-range index is an error, not something to repair.
  require_indices_in_range(triangles, num_triangles, 3, num_vertices_, "triangle");
  // Drop triangles with a repeated vertex.
  std::vector<int32_t> candidates;
  candidates.reserve(num_triangles);
  for (int64_t f = 0; f < num_triangles; ++f) {
    const int32_t* t = triangles + 3 * f;
    if (t[0] == t[1] || t[1] == t[2] || t[2] == t[0]) {
      ++report_.degenerate_triangles;
      report_.dropped_triangles.push_back(static_cast<int32_t>(f));
    } else {
      candidates.push_back(static_cast<int32_t>(f));
    }
  }
  // Drop exact duplicates (same vertex set, either orientation): bucket by smallest vertex, then
  // compare the sorted triples inside each small bucket. The first occurrence is kept.
  const int64_t k = static_cast<int64_t>(candidates.size());
  std::vector<std::array<int32_t, 3>> sorted(candidates.size());
#pragma omp parallel for schedule(static) if (k >= kParallelMin)
  for (int64_t i = 0; i < k; ++i) {
    const int32_t* t = triangles + 3 * size_t(candidates[i]);
    sorted[i] = {t[0], t[1], t[2]};
    std::sort(sorted[i].begin(), sorted[i].end());
  }
  std::vector<int32_t> bucket_offsets(num_vertices_ + 1, 0);
  for (const auto& t : sorted) ++bucket_offsets[t[0]];
  exclusive_scan(bucket_offsets);
  std::vector<int32_t> bucket(candidates.size());
  {
    std::vector<int32_t> fill(bucket_offsets.begin(), bucket_offsets.end() - 1);
    for (size_t i = 0; i < sorted.size(); ++i) bucket[fill[sorted[i][0]]++] = int32_t(i);
  }
  // Buckets are disjoint, so they are scanned in parallel.
  std::vector<uint8_t> duplicate(candidates.size(), 0);
#pragma omp parallel for schedule(static) if (num_vertices_ >= kParallelMin)
  for (int32_t v = 0; v < num_vertices_; ++v) {
    const int32_t b = bucket_offsets[v], e = bucket_offsets[v + 1];
    for (int32_t i = b; i < e; ++i) {
      if (duplicate[bucket[i]]) continue;
      for (int32_t j = i + 1; j < e; ++j)
        if (!duplicate[bucket[j]] && sorted[bucket[j]] == sorted[bucket[i]]) duplicate[bucket[j]] = 1;
    }
  }
  for (int64_t i = 0; i < k; ++i)
    if (duplicate[i]) {
      ++report_.duplicate_triangles;
      report_.dropped_triangles.push_back(candidates[i]);
    }
  const int64_t kept = k - report_.duplicate_triangles;
  face_source_.resize(kept);
  if (report_.duplicate_triangles == 0) {
    std::copy(candidates.begin(), candidates.end(), face_source_.begin());
  } else {
    int64_t j = 0;
    for (int64_t i = 0; i < k; ++i)
      if (!duplicate[i]) face_source_[j++] = candidates[i];
  }
  faces_.resize(3 * kept);
  int32_t zero_area = 0;
#pragma omp parallel for schedule(static) reduction(+ : zero_area) if (kept >= kParallelMin)
  for (int64_t i = 0; i < kept; ++i) {
    const int32_t* t = triangles + 3 * size_t(face_source_[i]);
    std::copy(t, t + 3, faces_.begin() + 3 * i);
    double n[3];
    cross(position(t[0]), position(t[1]), position(t[2]), n);
    if (n[0] == 0.0 && n[1] == 0.0 && n[2] == 0.0) ++zero_area;
  }
  report_.zero_area_triangles = zero_area;
  std::sort(report_.dropped_triangles.begin(), report_.dropped_triangles.end());
  if (faces_.empty())
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

// Sorts (key, vertex) pairs by key, ties by vertex, as std::sort on the pairs would: a stable
// least-significant-digit radix sort over the bits the keys use, on input in vertex order.
void radix_sort_keys(std::vector<std::pair<uint64_t, int32_t>>& keyed, int key_bits) {
  constexpr int kDigit = 11;
  std::vector<std::pair<uint64_t, int32_t>> other(keyed.size());
  std::vector<size_t> count(size_t(1) << kDigit);
  for (int shift = 0; shift < key_bits; shift += kDigit) {
    std::fill(count.begin(), count.end(), 0);
    for (const auto& k : keyed) ++count[(k.first >> shift) & ((1u << kDigit) - 1)];
    size_t sum = 0;
    for (auto& c : count) sum += std::exchange(c, sum);
    for (const auto& k : keyed) other[count[(k.first >> shift) & ((1u << kDigit) - 1)]++] = k;
    keyed.swap(other);
  }
}
}  // namespace

void Mesh::reorder_for_locality(const double* lo, const double* hi) {
  const int32_t n = num_vertices_;
  const double extent = std::max({hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2], 1e-300});
  std::vector<std::pair<uint64_t, int32_t>> keyed(n);
#pragma omp parallel for schedule(static) if (n >= kParallelMin)
  for (int32_t v = 0; v < n; ++v) {
    uint64_t key = 0;
    for (int k = 0; k < 3; ++k) {
      // Differences near the double range overflow to inf and inf / inf is NaN, which
      // std::clamp passes through: NaN goes to 0 (converting it to an integer is undefined).
      const double t = (positions_[3 * size_t(v) + k] - lo[k]) / extent;
      const double unit = t >= 0.0 ? std::min(t, 1.0) : 0.0;
      key |= spread_bits(uint64_t(unit * 2097151.0)) << k;
    }
    keyed[v] = {key, v};
  }
  radix_sort_keys(keyed, 63);
  vertex_source_.resize(n);
  vertex_index_.resize(n);
  std::vector<double> moved(positions_.size());
#pragma omp parallel for schedule(static) if (n >= kParallelMin)
  for (int32_t i = 0; i < n; ++i) {
    const int32_t old = keyed[i].second;
    vertex_source_[i] = old;
    vertex_index_[old] = i;
    for (int k = 0; k < 3; ++k) moved[3 * size_t(i) + k] = positions_[3 * size_t(old) + k];
  }
  positions_.swap(moved);
  const int64_t corners = static_cast<int64_t>(faces_.size());
#pragma omp parallel for schedule(static) if (corners >= kParallelMin)
  for (int64_t i = 0; i < corners; ++i) faces_[i] = vertex_index_[faces_[i]];
  // Faces in order of their lowest vertex (a stable counting sort keeps ties in input order).
  const int32_t m = num_faces();
  std::vector<int32_t> offsets(n + 1, 0);
  auto lowest = [&](int32_t f) { return std::min({faces_[3 * f], faces_[3 * f + 1], faces_[3 * f + 2]}); };
  for (int32_t f = 0; f < m; ++f) ++offsets[lowest(f) + 1];
  for (int32_t v = 0; v < n; ++v) offsets[v + 1] += offsets[v];
  std::vector<int32_t> order(m);
  for (int32_t f = 0; f < m; ++f) order[offsets[lowest(f)]++] = f;
  std::vector<int32_t> faces(faces_.size()), source(m);
#pragma omp parallel for schedule(static) if (m >= kParallelMin)
  for (int32_t i = 0; i < m; ++i) {
    for (int c = 0; c < 3; ++c) faces[3 * size_t(i) + c] = faces_[3 * size_t(order[i]) + c];
    source[i] = face_source_[order[i]];
  }
  faces_.swap(faces);
  face_source_.swap(source);
}

void Mesh::build_vertex_faces() {
  const int32_t m = num_faces();
  vertex_face_offsets_.assign(num_vertices_ + 1, 0);
  for (int32_t v : faces_) ++vertex_face_offsets_[v];
  exclusive_scan(vertex_face_offsets_);
  vertex_faces_.resize(faces_.size());
  std::vector<int32_t> fill(vertex_face_offsets_.begin(), vertex_face_offsets_.end() - 1);
  for (int32_t f = 0; f < m; ++f)
    for (int c = 0; c < 3; ++c) vertex_faces_[fill[faces_[3 * f + c]]++] = f;
  for (int32_t v = 0; v < num_vertices_; ++v)
    if (vertex_face_offsets_[v + 1] == vertex_face_offsets_[v]) ++report_.isolated_vertices;
}

void Mesh::build_adjacency_and_edges() {
  const int32_t n = num_vertices_;
  // Each vertex sees at most two neighbours per incident face: gather, sort, unique in place.
  std::vector<int32_t> scratch(2 * vertex_faces_.size());
  std::vector<int32_t> degree(n + 1, 0);
#pragma omp parallel for schedule(static) if (n >= kParallelMin)
  for (int32_t v = 0; v < n; ++v) {
    int32_t* out = scratch.data() + 2 * size_t(vertex_face_offsets_[v]);
    int32_t k = 0;
    for (int32_t i = vertex_face_offsets_[v]; i < vertex_face_offsets_[v + 1]; ++i) {
      const int32_t* t = &faces_[3 * size_t(vertex_faces_[i])];
      for (int c = 0; c < 3; ++c)
        if (t[c] != v) out[k++] = t[c];
    }
    std::sort(out, out + k);
    degree[v] = static_cast<int32_t>(std::unique(out, out + k) - out);
  }
  adjacency_offsets_ = degree;
  exclusive_scan(adjacency_offsets_);
  adjacency_.resize(adjacency_offsets_[n]);
  adjacency_edge_.resize(adjacency_offsets_[n]);
  // Edge ids: edges are numbered by their lower endpoint, then by the higher one.
  std::vector<int32_t> greater(n + 1, 0);
#pragma omp parallel for schedule(static) if (n >= kParallelMin)
  for (int32_t v = 0; v < n; ++v) {
    const int32_t* src = scratch.data() + 2 * size_t(vertex_face_offsets_[v]);
    std::copy(src, src + degree[v], adjacency_.begin() + adjacency_offsets_[v]);
    greater[v] = static_cast<int32_t>(src + degree[v] - std::upper_bound(src, src + degree[v], v));
  }
  std::vector<int32_t> edge_base = greater;
  exclusive_scan(edge_base);
  const int32_t num_edges = edge_base[n];
  edge_vertices_.resize(2 * size_t(num_edges));
#pragma omp parallel for schedule(static) if (n >= kParallelMin)
  for (int32_t v = 0; v < n; ++v) {
    const int32_t b = adjacency_offsets_[v], e = adjacency_offsets_[v + 1];
    const int32_t first_greater = e - greater[v];
    for (int32_t i = b; i < e; ++i) {
      const int32_t u = adjacency_[i];
      if (i >= first_greater) {
        const int32_t id = edge_base[v] + (i - first_greater);
        adjacency_edge_[i] = id;
        edge_vertices_[2 * size_t(id)] = v;
        edge_vertices_[2 * size_t(id) + 1] = u;
      }
    }
  }
  // Slots towards lower neighbours: v's lower neighbours u come in increasing order, and so do
  // the edges (u, v) as u grows, so one cursor per vertex fills them without searching.
  std::vector<int32_t> cursor(adjacency_offsets_.begin(), adjacency_offsets_.end() - 1);
  for (int32_t v = 0; v < n; ++v)
    for (int32_t i = adjacency_offsets_[v + 1] - greater[v]; i < adjacency_offsets_[v + 1]; ++i)
      adjacency_edge_[cursor[adjacency_[i]]++] = adjacency_edge_[i];
  // The edge of each face side, found by its lower endpoint among its higher neighbours.
  face_edges_.resize(faces_.size());
#pragma omp parallel for schedule(static) if (n >= kParallelMin)
  for (int32_t v = 0; v < n; ++v) {
    const int32_t* first = adjacency_.data() + adjacency_offsets_[v + 1] - greater[v];
    const int32_t* last = adjacency_.data() + adjacency_offsets_[v + 1];
    for (int32_t i = vertex_face_offsets_[v]; i < vertex_face_offsets_[v + 1]; ++i) {
      const int32_t f = vertex_faces_[i];
      const int32_t* t = &faces_[3 * size_t(f)];
      const int c = t[0] == v ? 0 : t[1] == v ? 1 : 2;
      for (int side : {c, (c + 2) % 3}) {
        const int32_t u = t[side == c ? (c + 1) % 3 : side];
        if (u > v) face_edges_[3 * size_t(f) + side] = edge_base[v] + int32_t(std::lower_bound(first, last, u) - first);
      }
    }
  }
}

int32_t Mesh::find_edge(int32_t a, int32_t b) const {
  if (a < 0 || a >= num_vertices_ || b < 0 || b >= num_vertices_) return -1;
  const auto* begin = adjacency_.data() + adjacency_offsets_[a];
  const auto* end = adjacency_.data() + adjacency_offsets_[a + 1];
  const auto* it = std::lower_bound(begin, end, b);
  return (it != end && *it == b) ? adjacency_edge_[it - adjacency_.data()] : -1;
}

void Mesh::build_edge_faces() {
  const int32_t m = num_faces();
  edge_face_offsets_.assign(num_edges() + 1, 0);
  for (int32_t e : face_edges_) ++edge_face_offsets_[e];
  exclusive_scan(edge_face_offsets_);
  edge_faces_.resize(face_edges_.size());
  std::vector<int32_t> fill(edge_face_offsets_.begin(), edge_face_offsets_.end() - 1);
  for (int32_t f = 0; f < m; ++f)
    for (int c = 0; c < 3; ++c) edge_faces_[fill[face_edges_[3 * f + c]]++] = f;
  inconsistent_edge_.assign(num_edges(), 0);
  for (int32_t e = 0; e < num_edges(); ++e) {
    const int32_t k = edge_face_count(e);
    if (k == 1) ++report_.boundary_edges;
    if (k >= 3) ++report_.nonmanifold_edges;
    if (k == 2) {
      // Consistent orientation: the two faces traverse the edge in opposite directions.
      const int32_t a = edge_vertices_[2 * e];
      auto forward = [&](int32_t f) {
        for (int c = 0; c < 3; ++c)
          if (face_edges_[3 * f + c] == e) return faces_[3 * f + c] == a;
        return false;
      };
      if (forward(edge_faces_[edge_face_offsets_[e]]) == forward(edge_faces_[edge_face_offsets_[e] + 1])) {
        ++report_.inconsistent_edges;
        inconsistent_edge_[e] = 1;
      }
    }
  }
}

void Mesh::compute_normals_and_weights() {
  const int32_t n = num_vertices_;
  const int32_t m = num_faces();
  // Area-weighted: the unnormalised face normal (twice the area) summed at each corner.
  std::vector<double> face_normals(3 * size_t(m));
#pragma omp parallel for schedule(static) if (m >= kParallelMin)
  for (int32_t f = 0; f < m; ++f) {
    const int32_t* t = &faces_[3 * size_t(f)];
    cross(position(t[0]), position(t[1]), position(t[2]), &face_normals[3 * size_t(f)]);
  }
  normals_.assign(3 * size_t(n), 0.0);
  weights_.assign(n, 0.0);
  vertex_areas_.assign(n, 0.0);
#pragma omp parallel for schedule(static) if (n >= kParallelMin)
  for (int32_t v = 0; v < n; ++v) {
    double sum[3] = {0, 0, 0}, area = 0.0;
    for (int32_t i = vertex_face_offsets_[v]; i < vertex_face_offsets_[v + 1]; ++i) {
      const double* fn = &face_normals[3 * size_t(vertex_faces_[i])];
      sum[0] += fn[0];
      sum[1] += fn[1];
      sum[2] += fn[2];
      area += std::sqrt(fn[0] * fn[0] + fn[1] * fn[1] + fn[2] * fn[2]) / 6.0;  // a third of half the cross
    }
    vertex_areas_[v] = area;
    const double len = std::sqrt(sum[0] * sum[0] + sum[1] * sum[1] + sum[2] * sum[2]);
    if (len > 0)
      for (int k = 0; k < 3; ++k) normals_[3 * size_t(v) + k] = sum[k] / len;
  }
  // Thesis eq. 4.1: x(v) = (|N_v| - sum_u n_v . n_u) / (2 |N_v|), the one-ring normal deviation.
#pragma omp parallel for schedule(static) if (n >= kParallelMin)
  for (int32_t v = 0; v < n; ++v) {
    const int32_t b = adjacency_offsets_[v], e = adjacency_offsets_[v + 1];
    if (b == e) continue;
    const double* nv = &normals_[3 * size_t(v)];
    double dots = 0.0;
    for (int32_t i = b; i < e; ++i) {
      const double* nu = &normals_[3 * size_t(adjacency_[i])];
      dots += nv[0] * nu[0] + nv[1] * nu[1] + nv[2] * nu[2];
    }
    const double x = (double(e - b) - dots) / (2.0 * double(e - b));
    weights_[v] = std::clamp(x, 0.0, 1.0);
  }
  // The means are summed in vertex order on one thread: an OpenMP reduction adds in an order
  // that depends on the number of threads, and so would change the last bits of the result.
  double total = 0.0, total_area = 0.0;
  int64_t counted = 0;
  for (int32_t v = 0; v < n; ++v) {
    total_area += vertex_areas_[v];
    if (adjacency_offsets_[v] == adjacency_offsets_[v + 1]) continue;
    total += weights_[v];
    ++counted;
  }
  mean_weight_ = counted ? total / double(counted) : 0.0;
  mean_vertex_area_ = counted ? total_area / double(counted) : 0.0;
}

bool Mesh::one_oriented_fan(int32_t v) const {
  const int32_t begin = vertex_face_offsets_[v], count = vertex_face_offsets_[v + 1] - begin;
  auto corner = [&](int32_t f) {
    const int32_t* t = &faces_[3 * size_t(f)];
    return t[0] == v ? 0 : t[1] == v ? 1 : 2;
  };
  // Each boundary side arriving at v starts a chain of faces; more than one chain is a pinch.
  int32_t start = vertex_faces_[begin], chains = 0;
  for (int32_t i = begin; i < begin + count; ++i) {
    const int32_t f = vertex_faces_[i];
    if (edge_face_count(face_edges_[3 * size_t(f) + (corner(f) + 2) % 3]) == 1) {
      start = f;
      if (++chains > 1) return false;
    }
  }
  // Walk across the sides leaving v (the next face arrives at v by the same edge) until the
  // chain ends or the cycle closes; one fan holds every face of v.
  int32_t f = start, visited = 1;
  while (visited <= count) {
    const int32_t e = face_edges_[3 * size_t(f) + corner(f)];
    if (edge_face_count(e) != 2) break;
    const int32_t* ef = &edge_faces_[edge_face_offsets_[e]];
    f = ef[0] == f ? ef[1] : ef[0];
    if (f == start) break;
    ++visited;
  }
  return visited == count;
}

void Mesh::compute_components_and_manifoldness() {
  const int32_t n = num_vertices_;
  component_.assign(n, -1);
  std::vector<int32_t> stack;
  int32_t components = 0;
  for (int32_t s = 0; s < n; ++s) {
    if (component_[s] >= 0 || adjacency_offsets_[s] == adjacency_offsets_[s + 1]) continue;
    component_[s] = components;
    stack.push_back(s);
    while (!stack.empty()) {
      const int32_t v = stack.back();
      stack.pop_back();
      for (int32_t i = adjacency_offsets_[v]; i < adjacency_offsets_[v + 1]; ++i)
        if (component_[adjacency_[i]] < 0) {
          component_[adjacency_[i]] = components;
          stack.push_back(adjacency_[i]);
        }
    }
    ++components;
  }
  report_.components = components;
  component_euler_.assign(components, 0);
  for (int32_t v = 0; v < n; ++v)
    if (component_[v] >= 0) ++component_euler_[component_[v]];
  for (int32_t e = 0; e < num_edges(); ++e) --component_euler_[component_[edge_vertices_[2 * e]]];
  for (int32_t f = 0; f < num_faces(); ++f) ++component_euler_[component_[faces_[3 * f]]];

  manifold_vertex_.assign(n, 1);
  int32_t pinched = 0;
#pragma omp parallel reduction(+ : pinched) if (n >= kParallelMin)
  {
    std::vector<int32_t> fan_of_slot;
#pragma omp for schedule(static)
    for (int32_t v = 0; v < n; ++v) {
      if (vertex_face_offsets_[v] == vertex_face_offsets_[v + 1]) continue;
      bool nonmanifold_edge = false, flipped = false;
      for (int32_t i = adjacency_offsets_[v]; i < adjacency_offsets_[v + 1]; ++i)
      {
        if (edge_face_count(adjacency_edge_[i]) > 2) nonmanifold_edge = true;
        if (inconsistent_edge_[adjacency_edge_[i]]) flipped = true;
      }
      // Fans only matter to tell pinched vertices; on consistently oriented two-face edges a
      // walk around v answers that without the general grouping.
      const int32_t fans = nonmanifold_edge ? 1
                           : flipped        ? vertex_fans(*this, v, [](int32_t) { return false; }, fan_of_slot)
                                            : (one_oriented_fan(v) ? 1 : 2);
      if (fans > 1 || nonmanifold_edge || flipped) {
        manifold_vertex_[v] = 0;
        if (fans > 1 && !nonmanifold_edge) ++pinched;  // pinched, not merely on a bad edge
      }
    }
  }
  report_.nonmanifold_vertices = pinched;
}

}  // namespace topstoc
