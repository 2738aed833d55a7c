#include "topstoc/edit/edit.hpp"

#include <algorithm>
#include <array>
#include <stdexcept>
#include <string>

#include "topstoc/core/incidence.hpp"

namespace topstoc {

namespace {

std::string edge_name(int32_t a, int32_t b) { return "(" + std::to_string(a) + ", " + std::to_string(b) + ")"; }

// Identity maps for an edit that keeps every input triangle in place.
void keep_all_faces(EditResult& r, int64_t num_triangles) {
  r.face_source.resize(size_t(num_triangles));
  r.corner_source.resize(3 * size_t(num_triangles));
  for (int64_t t = 0; t < num_triangles; ++t) r.face_source[t] = static_cast<int32_t>(t);
  for (int64_t c = 0; c < 3 * num_triangles; ++c) r.corner_source[c] = static_cast<int32_t>(c);
}

// Where each loop vertex sits in the loop (-1 elsewhere), after checking the loop itself.
std::vector<int32_t> loop_positions(const int32_t* loop, int32_t k, int32_t num_vertices) {
  if (k < 3) throw std::invalid_argument("a loop needs at least 3 vertices, got " + std::to_string(k));
  std::vector<int32_t> position(num_vertices, -1);
  for (int32_t i = 0; i < k; ++i) {
    const int32_t v = loop[i];
    if (v < 0 || v >= num_vertices)
      throw std::invalid_argument("loop entry " + std::to_string(i) + " is vertex " + std::to_string(v) +
                                  ", outside [0, " + std::to_string(num_vertices) + ")");
    if (position[v] >= 0)
      throw std::invalid_argument("loop visits vertex " + std::to_string(v) + " twice (entries " +
                                  std::to_string(position[v]) + " and " + std::to_string(i) +
                                  "): a cut needs a simple cycle");
    position[v] = i;
  }
  return position;
}

// One edge of a cut's side in the result, in the direction its triangle runs along it.
struct CutEdge {
  int32_t a, b;
};

// One cut_along_loop run: every loop vertex split into a copy per sector, the triangles
// re-pointed, and the cut's sides traced. The stages run in the order of run().
class LoopCut {
 public:
  LoopCut(const double* positions, int32_t num_vertices, const int32_t* triangles, int64_t num_triangles,
          const int32_t* loop, int32_t k, const VertexTriangles& around)
      : positions(positions), num_vertices(num_vertices), triangles(triangles), num_triangles(num_triangles),
        loop(loop), k(k), around(around), copy_of(k), sector_of(k) {}

  EditResult run() {
    r.vertices.assign(positions, positions + 3 * size_t(num_vertices));
    r.triangles.assign(triangles, triangles + 3 * num_triangles);
    r.vertex_source.resize(num_vertices);
    for (int32_t v = 0; v < num_vertices; ++v) r.vertex_source[v] = v;
    keep_all_faces(r, num_triangles);
    for (int32_t i = 0; i < k; ++i) split_vertex(i);
    repoint_corners();
    trace_sides(cut_edges());
    return std::move(r);
  }

 private:
  const double* positions;
  const int32_t num_vertices;
  const int32_t* triangles;
  const int64_t num_triangles;
  const int32_t* loop;
  const int32_t k;
  const VertexTriangles& around;
  EditResult r;
  std::vector<std::vector<int32_t>> copy_of;    // per loop vertex: the result vertex of each sector
  std::vector<std::vector<int32_t>> sector_of;  // per loop vertex: sector of each of its triangles
  std::vector<StarEdge> star;

  // Loop vertex i, checked to be manifold with loop edges inside the surface, gets a copy per
  // sector between the loop edges at it.
  void split_vertex(int32_t i) {
    const int32_t v = loop[i], prev = loop[(i + k - 1) % k], next = loop[(i + 1) % k];
    vertex_star(around, triangles, v, star);
    for (const StarEdge& e : star)
      if (e.count > 2)
        throw std::invalid_argument("loop vertex " + std::to_string(v) + " is non-manifold: edge " +
                                    edge_name(v, e.other) + " has " + std::to_string(e.count) + " triangles");
    std::vector<int32_t> fan;
    if (vertex_sectors(around, star, v, [](int32_t) { return false; }, fan) != 1)
      throw std::invalid_argument("loop vertex " + std::to_string(v) +
                                  " is non-manifold: its triangles form several fans joined only at the vertex");
    const StarEdge* forward = find_star_edge(star, next);
    if (!forward)
      throw std::invalid_argument("loop vertices " + std::to_string(v) + " and " + std::to_string(next) + " (entries " +
                                  std::to_string(i) + " and " + std::to_string((i + 1) % k) +
                                  ") are not joined by an edge: the loop must be a cycle of mesh edges");
    if (forward->count != 2)
      throw std::invalid_argument("loop edge " + edge_name(v, next) + " lies on the mesh boundary: a cut needs "
                                  "edges with a triangle on each side");
    const int32_t sectors =
        vertex_sectors(around, star, v, [&](int32_t w) { return w == prev || w == next; }, sector_of[i]);
    // The sector that runs along the loop (holds v -> next) keeps the vertex id; the others
    // get new vertices, appended in loop order.
    const int32_t first = forward->outgoing[0] ? forward->triangle[0]
                          : forward->outgoing[1] ? forward->triangle[1]
                                                 : std::min(forward->triangle[0], forward->triangle[1]);
    const int32_t slot = static_cast<int32_t>(
        std::lower_bound(around.list.begin() + around.begin(v), around.list.begin() + around.end(v), first) -
        (around.list.begin() + around.begin(v)));
    const int32_t keep = sector_of[i][slot];
    copy_of[i].assign(sectors, -1);
    copy_of[i][keep] = v;
    for (int32_t s = 0; s < sectors; ++s) {
      if (s == keep) continue;
      copy_of[i][s] = static_cast<int32_t>(r.vertex_source.size());
      r.vertex_source.push_back(v);
      r.vertices.insert(r.vertices.end(), positions + 3 * size_t(v), positions + 3 * size_t(v) + 3);
    }
  }

  // Re-point every triangle corner at a loop vertex to the copy of its sector.
  void repoint_corners() {
    for (int32_t i = 0; i < k; ++i) {
      const int32_t v = loop[i];
      for (int32_t j = around.begin(v); j < around.end(v); ++j) {
        const int32_t t = around.list[j];
        for (int c = 0; c < 3; ++c)
          if (triangles[3 * size_t(t) + c] == v) r.triangles[3 * size_t(t) + c] = copy_of[i][sector_of[i][j - around.begin(v)]];
      }
    }
  }

  // The cut's edges in the result: two per loop edge, one in each of its triangles, each in
  // the direction its triangle runs along it (the surface is on its left).
  std::vector<CutEdge> cut_edges() {
    std::vector<CutEdge> edges;
    edges.reserve(2 * size_t(k));
    for (int32_t i = 0; i < k; ++i) {
      const int32_t v = loop[i], next = loop[(i + 1) % k];
      vertex_star(around, triangles, v, star);
      const StarEdge* e = find_star_edge(star, next);
      for (int side = 0; side < 2; ++side) {
        const int32_t t = e->triangle[side];
        int32_t a = -1, b = -1;
        for (int c = 0; c < 3; ++c) {
          if (triangles[3 * size_t(t) + c] == v) a = r.triangles[3 * size_t(t) + c];
          if (triangles[3 * size_t(t) + c] == next) b = r.triangles[3 * size_t(t) + c];
        }
        if (e->outgoing[side]) edges.push_back({a, b}); else edges.push_back({b, a});
      }
    }
    return edges;
  }

  // The cut edges form the sides; traced as cycles (or paths where the loop met the mesh
  // boundary). Each copy has at most two cut edges: its sector holds one triangle of each loop
  // edge at it (one only, where the loop meets the mesh boundary). Traced without trusting
  // orientation, which a non-orientable surface may not have, then oriented by majority.
  void trace_sides(const std::vector<CutEdge>& edges) {
    std::vector<int32_t> ids;
    for (const CutEdge& e : edges) ids.push_back(e.a), ids.push_back(e.b);
    std::sort(ids.begin(), ids.end());
    ids.erase(std::unique(ids.begin(), ids.end()), ids.end());
    auto local = [&](int32_t v) { return int32_t(std::lower_bound(ids.begin(), ids.end(), v) - ids.begin()); };
    std::vector<std::array<int32_t, 2>> incident(ids.size(), {-1, -1});
    for (int32_t e = 0; e < int32_t(edges.size()); ++e)
      for (int32_t end : {local(edges[e].a), local(edges[e].b)}) incident[end][incident[end][0] < 0 ? 0 : 1] = e;
    std::vector<uint8_t> used(edges.size(), 0);
    auto trace = [&](int32_t start_vertex, bool closed) {
      CutSide side;
      side.closed = closed;
      int32_t v = start_vertex, votes = 0;
      for (;;) {
        side.vertices.push_back(ids[v]);
        const auto& inc = incident[v];
        const int32_t e = inc[0] >= 0 && !used[inc[0]] ? inc[0] : inc[1] >= 0 && !used[inc[1]] ? inc[1] : -1;
        if (e < 0) break;
        used[e] = 1;
        const int32_t w = local(edges[e].a) == v ? local(edges[e].b) : local(edges[e].a);
        votes += ids[v] == edges[e].a ? 1 : -1;
        if (closed && w == start_vertex) break;
        v = w;
      }
      if (votes < 0) std::reverse(side.vertices.begin() + (closed ? 1 : 0), side.vertices.end());
      r.cut_sides.push_back(std::move(side));
    };
    // Paths start at a copy with one cut edge; whatever remains is cycles.
    for (int32_t v = 0; v < int32_t(ids.size()); ++v)
      if (incident[v][1] < 0 && incident[v][0] >= 0 && !used[incident[v][0]]) trace(v, false);
    for (int32_t e = 0; e < int32_t(edges.size()); ++e)
      if (!used[e]) trace(local(edges[e].a), true);
    // Like boundary loops: cycles start at their lowest vertex, sides ordered by their first one
    // (so the side that kept the loop's own vertex ids comes first).
    for (CutSide& side : r.cut_sides)
      if (side.closed) std::rotate(side.vertices.begin(), std::min_element(side.vertices.begin(), side.vertices.end()),
                                   side.vertices.end());
    std::sort(r.cut_sides.begin(), r.cut_sides.end(),
              [](const CutSide& a, const CutSide& b) { return a.vertices.front() < b.vertices.front(); });
  }
};

}  // namespace

EditResult delete_faces(const double* positions, int32_t num_vertices, const int32_t* triangles, int64_t num_triangles,
                        const int32_t* faces, int64_t num_faces) {
  check_triangles(triangles, num_triangles, num_vertices, /*allow_repeated=*/true);
  std::vector<uint8_t> deleted(size_t(num_triangles), 0);
  for (int64_t i = 0; i < num_faces; ++i) {
    if (faces[i] < 0 || faces[i] >= num_triangles)
      throw std::invalid_argument("face entry " + std::to_string(i) + " is triangle " + std::to_string(faces[i]) +
                                  ", outside [0, " + std::to_string(num_triangles) + ")");
    deleted[faces[i]] = 1;
  }
  // 0: in no triangle, 1: only in deleted triangles, 2: in a kept triangle.
  std::vector<uint8_t> use(num_vertices, 0);
  for (int64_t t = 0; t < num_triangles; ++t)
    for (int c = 0; c < 3; ++c) {
      uint8_t& u = use[triangles[3 * t + c]];
      u = std::max<uint8_t>(u, deleted[t] ? 1 : 2);
    }
  EditResult r;
  std::vector<int32_t> new_id(num_vertices, -1);
  for (int32_t v = 0; v < num_vertices; ++v) {
    if (use[v] == 1) continue;
    new_id[v] = static_cast<int32_t>(r.vertex_source.size());
    r.vertex_source.push_back(v);
    r.vertices.insert(r.vertices.end(), positions + 3 * size_t(v), positions + 3 * size_t(v) + 3);
  }
  for (int64_t t = 0; t < num_triangles; ++t) {
    if (deleted[t]) continue;
    r.face_source.push_back(static_cast<int32_t>(t));
    for (int c = 0; c < 3; ++c) {
      r.triangles.push_back(new_id[triangles[3 * t + c]]);
      r.corner_source.push_back(static_cast<int32_t>(3 * t + c));
    }
  }
  return r;
}

EditResult cut_along_loop(const double* positions, int32_t num_vertices, const int32_t* triangles,
                          int64_t num_triangles, const int32_t* loop, int32_t k) {
  check_triangles(triangles, num_triangles, num_vertices, /*allow_repeated=*/false);
  const std::vector<int32_t> position = loop_positions(loop, k, num_vertices);
  std::vector<uint8_t> on_loop(num_vertices, 0);
  for (int32_t i = 0; i < k; ++i) on_loop[loop[i]] = 1;
  const VertexTriangles around = vertex_triangles(triangles, num_triangles, num_vertices, on_loop.data());
  return LoopCut(positions, num_vertices, triangles, num_triangles, loop, k, around).run();
}

}  // namespace topstoc
