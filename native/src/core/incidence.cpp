#include "topstoc/core/incidence.hpp"

#include <algorithm>
#include <stdexcept>
#include <string>

#include "topstoc/core/validate.hpp"

namespace topstoc {

void check_positions(const double* positions, int32_t num_vertices, const std::vector<int32_t>* vertices) {
  if (vertices) {
    for (int32_t v : *vertices) require_finite_position(positions, v);
  } else {
    require_finite_positions(positions, num_vertices);
  }
}

void check_triangles(const int32_t* triangles, int64_t num_triangles, int32_t num_vertices, bool allow_repeated) {
  if (num_triangles > INT32_MAX / 3) throw std::invalid_argument("mesh is too large: more than 2^31 / 3 triangles");
  require_indices_in_range(triangles, num_triangles, 3, num_vertices, "triangle");
  for (int64_t t = 0; t < num_triangles; ++t) {
    const int32_t* c = triangles + 3 * t;
    if (!allow_repeated && (c[0] == c[1] || c[1] == c[2] || c[2] == c[0]))
      throw std::invalid_argument("triangle " + std::to_string(t) + " (" + std::to_string(c[0]) + ", " +
                                  std::to_string(c[1]) + ", " + std::to_string(c[2]) +
                                  ") repeats a vertex: delete degenerate triangles first");
  }
}

VertexTriangles vertex_triangles(const int32_t* triangles, int64_t num_triangles, int32_t num_vertices,
                                 const uint8_t* only) {
  VertexTriangles out;
  out.offsets.assign(size_t(num_vertices) + 1, 0);
  for (int64_t i = 0; i < 3 * num_triangles; ++i) {
    const int32_t v = triangles[i];
    if (!only || only[v]) ++out.offsets[v + 1];
  }
  for (int32_t v = 0; v < num_vertices; ++v) out.offsets[v + 1] += out.offsets[v];
  out.list.resize(out.offsets[num_vertices]);
  std::vector<int32_t> cursor(out.offsets.begin(), out.offsets.end() - 1);
  // Triangles are visited in increasing order, so every list comes out sorted. A triangle with
  // a repeated vertex is listed once per corner; callers reject those before looking at stars.
  for (int64_t t = 0; t < num_triangles; ++t)
    for (int k = 0; k < 3; ++k) {
      const int32_t v = triangles[3 * t + k];
      if (!only || only[v]) out.list[cursor[v]++] = static_cast<int32_t>(t);
    }
  return out;
}

void vertex_star(const VertexTriangles& around, const int32_t* triangles, int32_t v, std::vector<StarEdge>& star) {
  // Each triangle of v contributes its two edges at v, v -> next (outgoing) and prev -> v, as one
  // entry each; sorted by the other end, the entries of one edge are then merged in place (no
  // scratch of its own: a thread_local one was destroyed on freed memory under mingw-w64).
  star.clear();
  for (int32_t i = around.begin(v); i < around.end(v); ++i) {
    const int32_t t = around.list[i];
    const int32_t* c = triangles + 3 * size_t(t);
    const int k = c[0] == v ? 0 : c[1] == v ? 1 : 2;
    star.push_back(StarEdge{c[(k + 1) % 3], 1, {t, -1}, {true, false}});
    star.push_back(StarEdge{c[(k + 2) % 3], 1, {t, -1}, {false, false}});
  }
  std::sort(star.begin(), star.end(), [](const StarEdge& a, const StarEdge& b) {
    return a.other != b.other ? a.other < b.other : a.triangle[0] < b.triangle[0];
  });
  size_t kept = 0;
  for (size_t i = 0; i < star.size(); ++i) {
    const StarEdge side = star[i];
    if (kept == 0 || star[kept - 1].other != side.other) {
      star[kept++] = side;
      continue;
    }
    StarEdge& e = star[kept - 1];
    if (e.count < 2) {
      e.triangle[e.count] = side.triangle[0];
      e.outgoing[e.count] = side.outgoing[0];
    }
    ++e.count;
  }
  star.resize(kept);
}

const StarEdge* find_star_edge(const std::vector<StarEdge>& star, int32_t other) {
  auto it = std::lower_bound(star.begin(), star.end(), other,
                             [](const StarEdge& e, int32_t value) { return e.other < value; });
  return it != star.end() && it->other == other ? &*it : nullptr;
}

}  // namespace topstoc
