#include "topstoc/core/mesh_edges.hpp"

#include <algorithm>
#include <memory>


#include "topstoc/core/incidence.hpp"
#include "topstoc/core/parallel.hpp"

namespace topstoc {

namespace {

// The corner after c in its triangle: the other end of c's edge.
inline int32_t next_corner(int32_t c) { return c % 3 == 2 ? c - 2 : c + 1; }

// One corner of a bucket: the higher end of its edge, and the corner.
struct BucketEntry {
  int32_t higher, corner;
};

// Per higher end w: the lower vertex it was last met with, and that edge.
struct Mark {
  int32_t lower = -1, edge = 0;
};

// Visits the distinct edges whose lower vertex is v, in order of their first corner:
// emit(mark, higher, corner, fresh) for every corner of v's bucket, `fresh` true on an edge's
// first. `marks[w].lower == v` marks the higher ends met already; no sort needed (sorting each
// bucket cost more than the rest of the function on a 150k-triangle mesh).
template <class Emit>
void visit_bucket(const std::vector<int32_t>& offsets, const BucketEntry* bucket, int32_t v, std::vector<Mark>& marks,
                  Emit emit) {
  for (int32_t i = offsets[v]; i < offsets[v + 1]; ++i) {
    const BucketEntry entry = bucket[i];
    Mark& mark = marks[entry.higher];
    const bool fresh = mark.lower != v;
    mark.lower = v;
    emit(mark, entry.higher, entry.corner, fresh);
  }
}

}  // namespace

MeshEdges mesh_edges(const int32_t* triangles, int64_t num_triangles, int32_t num_vertices) {
  check_triangles(triangles, num_triangles, num_vertices, false);
  const int32_t corners = int32_t(3 * num_triangles);  // check_triangles limits the count
  auto lower_end = [&](int32_t c) { return std::min(triangles[c], triangles[next_corner(c)]); };
  // Corners bucketed by their edge's lower vertex (CSR), in corner order: the order of edges
  // below follows from the triangles alone. Each entry carries its edge's higher end, so the
  // passes below read only the buckets (reading the triangles there, in bucket order, jumped
  // about the whole triangle array).
  std::vector<int32_t> offsets(size_t(num_vertices) + 1, 0);
  for (int32_t c = 0; c < corners; ++c) ++offsets[size_t(lower_end(c)) + 1];
  for (int32_t v = 0; v < num_vertices; ++v) offsets[v + 1] += offsets[v];
  // (Not value-initialised: every entry is written below.)
  std::unique_ptr<BucketEntry[]> bucket(new BucketEntry[size_t(corners)]);
  {
    std::vector<int32_t> cursor(offsets.begin(), offsets.end() - 1);
    for (int32_t c = 0; c < corners; ++c) {
      const int32_t a = triangles[c], b = triangles[next_corner(c)];
      bucket[cursor[std::min(a, b)]++] = {std::max(a, b), c};
    }
  }
  MeshEdges out;
  out.corner_edge.resize(corners);
  const int team = num_vertices >= kParallelMin ? max_threads() : 1;
  if (team == 1) {
    // One pass, numbering the edges as they are met.
    std::vector<Mark> marks(num_vertices);
    int32_t edges = 0;
    out.vertices.reserve(corners);  // a closed surface has half as many edges as corners
    for (int32_t v = 0; v < num_vertices; ++v)
      visit_bucket(offsets, bucket.get(), v, marks, [&](Mark& mark, int32_t higher, int32_t corner, bool fresh) {
        if (fresh) {
          mark.edge = edges++;
          out.vertices.push_back(v);
          out.vertices.push_back(higher);
        }
        out.corner_edge[corner] = mark.edge;
      });
    return out;
  }
  // Threads: count each lower vertex's distinct edges, then number them from the prefix sums.
  // Each thread keeps its own marks.
  std::vector<int32_t> first_edge(size_t(num_vertices) + 1, 0);
  parallel_region(team, [&](Team& t) {
    std::vector<Mark> marks(num_vertices);
    t.for_static(0, num_vertices, [&](int32_t v) {
      int32_t distinct = 0;
      visit_bucket(offsets, bucket.get(), v, marks, [&](Mark&, int32_t, int32_t, bool fresh) { distinct += fresh; });
      first_edge[size_t(v) + 1] = distinct;
    });
    t.barrier();  // (an OpenMP for ends with one)
    t.single([&] {
      for (int32_t v = 0; v < num_vertices; ++v) first_edge[v + 1] += first_edge[v];
      out.vertices.resize(2 * size_t(first_edge[num_vertices]));
    });
    std::fill(marks.begin(), marks.end(), Mark());
    t.for_static(0, num_vertices, [&](int32_t v) {
      int32_t next = first_edge[v];
      visit_bucket(offsets, bucket.get(), v, marks, [&](Mark& mark, int32_t higher, int32_t corner, bool fresh) {
        if (fresh) {
          mark.edge = next;
          out.vertices[2 * size_t(next)] = v;
          out.vertices[2 * size_t(next) + 1] = higher;
          ++next;
        }
        out.corner_edge[corner] = mark.edge;
      });
    });
  });
  return out;
}

}  // namespace topstoc
