// Incidence on the caller's raw arrays: which triangles touch a vertex, which edges leave it,
// how its triangles group into fans. Editing works on exactly the triangles the caller has (the
// prepared Mesh drops and renumbers), so these helpers take plain arrays and copy nothing.
#pragma once

#include <cstdint>
#include <vector>

namespace topstoc {

/// Throws std::invalid_argument naming the first vertex in `vertices` (or every vertex when
/// `vertices` is null) with a non-finite coordinate.
void check_positions(const double* positions, int32_t num_vertices, const std::vector<int32_t>* vertices = nullptr);

/// Throws std::invalid_argument naming the first triangle with an index outside
/// [0, num_vertices) or, unless `allow_repeated`, a vertex used twice.
void check_triangles(const int32_t* triangles, int64_t num_triangles, int32_t num_vertices, bool allow_repeated);

/// Triangles around each vertex, CSR: the triangles of v are list[offsets[v] .. offsets[v + 1])
/// in increasing order. Built in O(n + m).
struct VertexTriangles {
  std::vector<int32_t> offsets;  ///< num_vertices + 1 entries
  std::vector<int32_t> list;
  int32_t begin(int32_t v) const { return offsets[v]; }
  int32_t end(int32_t v) const { return offsets[v + 1]; }
  int32_t count(int32_t v) const { return offsets[v + 1] - offsets[v]; }
};

/// With `only` (one flag per vertex), only flagged vertices get their lists (the others are
/// empty): a loop or hole needs its own vertices' triangles, not the whole mesh's.
VertexTriangles vertex_triangles(const int32_t* triangles, int64_t num_triangles, int32_t num_vertices,
                                 const uint8_t* only = nullptr);

/// One edge leaving v: the other end, how many triangles hold it, the first two of them and
/// whether each traverses the edge from v to `other` (its orientation).
struct StarEdge {
  int32_t other = -1;
  int32_t count = 0;
  int32_t triangle[2] = {-1, -1};
  bool outgoing[2] = {false, false};
};

/// The edges leaving v, sorted by `other`. `triangles` must have no repeated vertex.
void vertex_star(const VertexTriangles& around, const int32_t* triangles, int32_t v, std::vector<StarEdge>& star);

/// Finds the star entry for the edge (v, other), or null.
const StarEdge* find_star_edge(const std::vector<StarEdge>& star, int32_t other);

/// Groups v's triangles into sectors: triangles sharing an edge (v, w) with exactly two
/// triangles are joined unless blocked(w). sector[i] receives the sector (0, 1, ... in order of
/// first appearance) of the i-th triangle of v's list. Returns the number of sectors; with
/// nothing blocked this is the number of fans (1 for a manifold vertex).
template <class Blocked>
int32_t vertex_sectors(const VertexTriangles& around, const std::vector<StarEdge>& star, int32_t v, Blocked blocked,
                       std::vector<int32_t>& sector) {
  const int32_t begin = around.begin(v), count = around.count(v);
  sector.resize(count);
  for (int32_t i = 0; i < count; ++i) sector[i] = i;
  auto slot = [&](int32_t t) {  // position of triangle t in v's sorted list
    int32_t lo = 0, hi = count;
    while (lo < hi) {
      const int32_t mid = (lo + hi) / 2;
      if (around.list[begin + mid] < t) lo = mid + 1; else hi = mid;
    }
    return lo;
  };
  auto find = [&](int32_t i) {
    while (sector[i] != i) i = sector[i] = sector[sector[i]];
    return i;
  };
  for (const StarEdge& e : star) {
    if (e.count != 2 || blocked(e.other)) continue;
    const int32_t a = find(slot(e.triangle[0])), b = find(slot(e.triangle[1]));
    if (a != b) sector[a < b ? b : a] = a < b ? a : b;
  }
  std::vector<int32_t> label_of_root(count, -1), label(count);
  int32_t sectors = 0;
  for (int32_t i = 0; i < count; ++i) {
    const int32_t root = find(i);
    if (label_of_root[root] < 0) label_of_root[root] = sectors++;
    label[i] = label_of_root[root];
  }
  sector.swap(label);
  return sectors;
}

}  // namespace topstoc
