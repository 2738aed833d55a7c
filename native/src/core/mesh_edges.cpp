#include "topstoc/core/mesh_edges.hpp"

#include <algorithm>

#include "topstoc/core/incidence.hpp"
#include "topstoc/core/parallel.hpp"

namespace topstoc {

namespace {

// The corner after c in its triangle: the other end of c's edge.
inline int32_t next_corner(int32_t c) { return c % 3 == 2 ? c - 2 : c + 1; }

// Visits the distinct edges whose lower vertex is v, in order of their first corner:
// emit(higher, corner) for every corner of v's bucket, with `fresh` true on an edge's first.
// `seen[w] == v` marks the higher ends met already; no sort needed (sorting each bucket cost
// more than the rest of the function on a 150k-triangle mesh).
template <class Emit>
void visit_bucket(const int32_t* triangles, const std::vector<int32_t>& offsets, const std::vector<int32_t>& bucket,
                  int32_t v, std::vector<int32_t>& seen, Emit emit) {
  for (int32_t i = offsets[v]; i < offsets[v + 1]; ++i) {
    const int32_t corner = bucket[i];
    const int32_t higher = std::max(triangles[corner], triangles[next_corner(corner)]);
    const bool fresh = seen[higher] != v;
    seen[higher] = v;
    emit(higher, corner, fresh);
  }
}

}  // namespace

MeshEdges mesh_edges(const int32_t* triangles, int64_t num_triangles, int32_t num_vertices) {
  check_triangles(triangles, num_triangles, num_vertices, false);
  const int32_t corners = int32_t(3 * num_triangles);  // check_triangles limits the count
  auto lower_end = [&](int32_t c) { return std::min(triangles[c], triangles[next_corner(c)]); };
  // Corners bucketed by their edge's lower vertex (CSR), in corner order: the order of edges
  // below follows from the triangles alone.
  std::vector<int32_t> offsets(size_t(num_vertices) + 1, 0);
  for (int32_t c = 0; c < corners; ++c) ++offsets[size_t(lower_end(c)) + 1];
  for (int32_t v = 0; v < num_vertices; ++v) offsets[v + 1] += offsets[v];
  std::vector<int32_t> bucket(corners);
  {
    std::vector<int32_t> cursor(offsets.begin(), offsets.end() - 1);
    for (int32_t c = 0; c < corners; ++c) bucket[cursor[lower_end(c)]++] = c;
  }
  // Two passes over the lower vertices: count each one's distinct edges, then number them
  // from the prefix sums. Each thread keeps its own marks.
  std::vector<int32_t> first_edge(size_t(num_vertices) + 1, 0);
  MeshEdges out;
  out.corner_edge.resize(corners);
  const bool parallel = num_vertices >= kParallelMin;
#pragma omp parallel if (parallel)
  {
    std::vector<int32_t> seen(num_vertices, -1);
#pragma omp for schedule(static)
    for (int32_t v = 0; v < num_vertices; ++v) {
      int32_t distinct = 0;
      visit_bucket(triangles, offsets, bucket, v, seen, [&](int32_t, int32_t, bool fresh) { distinct += fresh; });
      first_edge[size_t(v) + 1] = distinct;
    }
#pragma omp single
    {
      for (int32_t v = 0; v < num_vertices; ++v) first_edge[v + 1] += first_edge[v];
      out.vertices.resize(2 * size_t(first_edge[num_vertices]));
    }
    std::fill(seen.begin(), seen.end(), -1);
    std::vector<int32_t> edge_of(num_vertices);  // edge_of[w]: the edge (v, w), once seen[w] == v
#pragma omp for schedule(static)
    for (int32_t v = 0; v < num_vertices; ++v) {
      int32_t next = first_edge[v];
      visit_bucket(triangles, offsets, bucket, v, seen, [&](int32_t higher, int32_t corner, bool fresh) {
        if (fresh) {
          edge_of[higher] = next;
          out.vertices[2 * size_t(next)] = v;
          out.vertices[2 * size_t(next) + 1] = higher;
          ++next;
        }
        out.corner_edge[corner] = edge_of[higher];
      });
    }
  }
  return out;
}

}  // namespace topstoc
