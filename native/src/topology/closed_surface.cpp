#include "topology/closed_surface.hpp"

#include <algorithm>
#include <cmath>

#include "core/fans.hpp"

namespace topstoc {

double ClosedSurface::edge_length(int32_t e) const {
  const double* a = position(edge_vertices[2 * size_t(e)]);
  const double* b = position(edge_vertices[2 * size_t(e) + 1]);
  return std::sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) + (a[2] - b[2]) * (a[2] - b[2]));
}

int32_t ClosedSurface::find_edge(int32_t a, int32_t b) const {
  for (int32_t i = adjacency_offsets[a]; i < adjacency_offsets[a + 1]; ++i)
    if (adjacency[i] == b) return adjacency_edge[i];
  return -1;
}

std::vector<std::vector<int32_t>> component_vertices(const Mesh& mesh) {
  std::vector<std::vector<int32_t>> out(mesh.num_components());
  const auto& component = mesh.component();
  for (int32_t v = 0; v < mesh.num_vertices(); ++v)
    if (component[v] >= 0) out[component[v]].push_back(v);
  return out;
}

namespace {

// Local numbering of a sorted subset of ids: a dense table when the subset is a large part of
// the whole (one big component), a binary search otherwise (many small components).
class LocalIds {
 public:
  LocalIds(const std::vector<int32_t>& sorted_ids, int32_t universe) : ids_(sorted_ids) {
    if (sorted_ids.size() * 8 >= size_t(universe)) {
      dense_.assign(universe, -1);
      for (size_t i = 0; i < sorted_ids.size(); ++i) dense_[sorted_ids[i]] = int32_t(i);
    }
  }
  int32_t operator()(int32_t id) const {
    if (!dense_.empty()) return dense_[id];
    return int32_t(std::lower_bound(ids_.begin(), ids_.end(), id) - ids_.begin());
  }

 private:
  const std::vector<int32_t>& ids_;
  std::vector<int32_t> dense_;
};

std::string edge_name(const Mesh& mesh, int32_t e) {
  const auto& source = mesh.vertex_source();
  int32_t a = source[mesh.edge_vertices()[2 * size_t(e)]], b = source[mesh.edge_vertices()[2 * size_t(e) + 1]];
  if (a > b) std::swap(a, b);
  return "edge " + std::to_string(a) + "-" + std::to_string(b);
}


}  // namespace

std::vector<SurfaceCheck> check_closed_surfaces(const Mesh& mesh, const std::vector<std::vector<int32_t>>& components) {
  const auto& source = mesh.vertex_source();
  const auto& component = mesh.component();
  std::vector<SurfaceCheck> checks(components.size());
  for (size_t c = 0; c < components.size(); ++c) {
    checks[c].vertices = int32_t(components[c].size());
    int32_t first = INT32_MAX;
    for (int32_t v : components[c]) first = std::min(first, source[v]);
    checks[c].first_vertex = first;
  }
  // Edges: boundary and non-manifold ones, named by their first occurrence.
  std::vector<int32_t> first_boundary(components.size(), -1), first_nonmanifold(components.size(), -1);
  for (int32_t e = 0; e < mesh.num_edges(); ++e) {
    const int32_t c = component[mesh.edge_vertices()[2 * size_t(e)]];
    SurfaceCheck& check = checks[c];
    ++check.edges;
    const int32_t k = mesh.edge_face_count(e);
    if (k == 1) {
      ++check.boundary_edges;
      if (first_boundary[c] < 0) first_boundary[c] = e;
    } else if (k > 2) {
      ++check.nonmanifold_edges;
      if (first_nonmanifold[c] < 0) first_nonmanifold[c] = e;
    }
  }
  for (int32_t f = 0; f < mesh.num_faces(); ++f) ++checks[component[mesh.faces()[3 * size_t(f)]]].faces;
  // Pinched vertices: several fans of triangles meeting only at the vertex.
  std::vector<int32_t> fan_of_slot;
  std::vector<int32_t> first_pinched(components.size(), -1);
  for (size_t c = 0; c < components.size(); ++c) {
    if (checks[c].nonmanifold_edges) continue;
    for (int32_t v : components[c])
      if (!mesh.manifold_vertex()[v] && vertex_fans(mesh, v, [](int32_t) { return false; }, fan_of_slot) > 1) {
        ++checks[c].pinched_vertices;
        if (first_pinched[c] < 0 || source[v] < source[first_pinched[c]]) first_pinched[c] = v;
      }
  }
  // Orientability: propagate a flip bit across edges; a contradiction means no consistent
  // orientation. Consistently oriented input (the usual case) needs no search.
  std::vector<int8_t> flip(mesh.report().inconsistent_edges ? mesh.num_faces() : 0, -1);
  std::vector<int32_t> stack;
  for (int32_t start = 0; start < int32_t(flip.size()); ++start) {
    const int32_t c = component[mesh.faces()[3 * size_t(start)]];
    SurfaceCheck& check = checks[c];
    if (flip[start] >= 0 || check.nonmanifold_edges || check.pinched_vertices || !check.problem.empty()) continue;
    flip[start] = 0;
    stack.assign(1, start);
    while (!stack.empty() && check.problem.empty()) {
      const int32_t f = stack.back();
      stack.pop_back();
      for (int k = 0; k < 3; ++k) {
        const int32_t e = mesh.face_edges()[3 * size_t(f) + k];
        if (mesh.edge_face_count(e) != 2) continue;
        const int32_t o = mesh.edge_face_offsets()[e];
        const int32_t g = mesh.edge_faces()[o] == f ? mesh.edge_faces()[o + 1] : mesh.edge_faces()[o];
        // Consistent neighbours run along the edge in opposite directions.
        const int8_t want = int8_t(flip[f] ^ (mesh.runs_forward(f, e) == mesh.runs_forward(g, e)));
        if (flip[g] < 0) {
          flip[g] = want;
          stack.push_back(g);
        } else if (flip[g] != want) {
          check.problem = "non-orientable";
          check.detail = "no consistent orientation exists (a Moebius band runs through " + edge_name(mesh, e) + ")";
          break;
        }
      }
    }
  }
  // Boundary loops of manifold components: on a manifold each boundary vertex has two boundary
  // edges, so the loops are the connected components of the boundary edges.
  std::vector<int32_t> parent(mesh.num_vertices(), -1);
  auto find = [&](int32_t v) {
    while (parent[v] != v) v = parent[v] = parent[parent[v]];
    return v;
  };
  for (int32_t e = 0; e < mesh.num_edges(); ++e) {
    if (mesh.edge_face_count(e) != 1) continue;
    const int32_t a = mesh.edge_vertices()[2 * size_t(e)], b = mesh.edge_vertices()[2 * size_t(e) + 1];
    for (int32_t v : {a, b})
      if (parent[v] < 0) {
        parent[v] = v;
        ++checks[component[v]].boundary_loops;
      }
    const int32_t ra = find(a), rb = find(b);
    if (ra != rb) {
      parent[ra] = rb;
      --checks[component[a]].boundary_loops;
    }
  }
  for (size_t c = 0; c < components.size(); ++c) {
    SurfaceCheck& check = checks[c];
    if (check.nonmanifold_edges) {
      check.problem = "non-manifold";
      check.detail = std::to_string(check.nonmanifold_edges) + " edges have three or more triangles (first: " +
                     edge_name(mesh, first_nonmanifold[c]) + ")";
    } else if (check.pinched_vertices) {
      check.problem = "non-manifold";
      check.detail = std::to_string(check.pinched_vertices) + " vertices are pinched (triangle fans meeting at one vertex only; first: vertex " +
                     std::to_string(source[first_pinched[c]]) + ")";
    } else if (check.boundary_edges && check.problem.empty()) {
      check.problem = "open";
      check.detail = std::to_string(check.boundary_edges) + " boundary edges (first: " + edge_name(mesh, first_boundary[c]) + ")";
    }
  }
  return checks;
}

ClosedSurface extract_surface(const Mesh& mesh, const std::vector<int32_t>& vertices) {
  ClosedSurface s;
  const int32_t n = int32_t(vertices.size());
  s.mesh_vertex = vertices;
  const LocalIds local(vertices, mesh.num_vertices());
  s.positions.resize(3 * size_t(n));
  for (int32_t i = 0; i < n; ++i)
    for (int k = 0; k < 3; ++k) s.positions[3 * size_t(i) + k] = mesh.position(vertices[i])[k];
  // Faces and edges of the component, numbered in the mesh's order.
  std::vector<int32_t> faces, edges;
  for (int32_t v : vertices)
    mesh.for_each_face(v, [&](int32_t f) {
      if (mesh.faces()[3 * size_t(f)] == v) faces.push_back(f);  // once per face, from its first corner
    });
  std::sort(faces.begin(), faces.end());
  for (int32_t v : vertices)
    for (int32_t i = mesh.adjacency_offsets()[v]; i < mesh.adjacency_offsets()[v + 1]; ++i)
      if (mesh.adjacency()[i] > v) edges.push_back(mesh.adjacency_edge()[i]);
  std::sort(edges.begin(), edges.end());
  const LocalIds local_edge(edges, mesh.num_edges()), local_face(faces, mesh.num_faces());

  s.triangles.resize(3 * faces.size());
  s.face_edges.resize(3 * faces.size());
  for (size_t f = 0; f < faces.size(); ++f)
    for (int c = 0; c < 3; ++c) {
      s.triangles[3 * f + c] = local(mesh.faces()[3 * size_t(faces[f]) + c]);
      s.face_edges[3 * f + c] = local_edge(mesh.face_edges()[3 * size_t(faces[f]) + c]);
    }
  s.edge_vertices.resize(2 * edges.size());
  s.edge_faces.resize(2 * edges.size());
  for (size_t e = 0; e < edges.size(); ++e) {
    const int32_t me = edges[e];
    s.edge_vertices[2 * e] = local(mesh.edge_vertices()[2 * size_t(me)]);
    s.edge_vertices[2 * e + 1] = local(mesh.edge_vertices()[2 * size_t(me) + 1]);
    const int32_t o = mesh.edge_face_offsets()[me];
    s.edge_faces[2 * e] = local_face(mesh.edge_faces()[o]);
    s.edge_faces[2 * e + 1] = local_face(mesh.edge_faces()[o + 1]);
  }
  s.adjacency_offsets.resize(size_t(n) + 1);
  s.adjacency_offsets[0] = 0;
  for (int32_t i = 0; i < n; ++i) {
    const int32_t v = vertices[i];
    for (int32_t j = mesh.adjacency_offsets()[v]; j < mesh.adjacency_offsets()[v + 1]; ++j) {
      s.adjacency.push_back(local(mesh.adjacency()[j]));
      s.adjacency_edge.push_back(local_edge(mesh.adjacency_edge()[j]));
    }
    s.adjacency_offsets[i + 1] = int32_t(s.adjacency.size());
  }
  return s;
}

}  // namespace topstoc
