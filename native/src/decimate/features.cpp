#include "topstoc/decimate/features.hpp"
#include "topstoc/core/parallel.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "core/fans.hpp"
#include "core/per_thread.hpp"
#include "core/portable.hpp"
#include "curve_bends.hpp"
#include "pinched_fans.hpp"

namespace topstoc {

int32_t FeatureLayout::chi_of(const Mesh& mesh, int32_t v) const {
  if (!chi_constant.empty()) return chi_constant[v];
  const auto& ao = mesh.adjacency_offsets();
  return 6 * sectors_of(mesh, v) - 3 * (ao[v + 1] - ao[v]) + 2 * mesh.face_count(v);  // one copy per edge
}

int32_t FeatureLayout::sectors_of(const Mesh& mesh, int32_t v) const {
  if (!sectors.empty()) return sectors[v];
  return mesh.in_faces(v) ? 1 : 0;
}

int32_t FeatureLayout::sector_of(const Mesh& mesh, int32_t v, int32_t f) const {
  if (sectors_of(mesh, v) <= 1) {  // one sector: no slot table needed
    const int32_t* t = &mesh.faces()[3 * size_t(f)];
    return t[0] == v || t[1] == v || t[2] == v ? 0 : -1;
  }
  const auto it = std::lower_bound(sector_slot_vertex.begin(), sector_slot_vertex.end(), v);
  if (it == sector_slot_vertex.end() || *it != v) return -1;
  const int32_t* sector = sector_of_slot.data() + sector_slot_offsets[it - sector_slot_vertex.begin()];
  int32_t found = -1, slot = 0;
  mesh.for_each_face(v, [&](int32_t g) {
    if (g == f) found = sector[slot];
    ++slot;
  });
  return found;
}

namespace {

void mark_feature_edges(const Mesh& mesh, const int32_t* face_region, int64_t face_region_count,
                        const int32_t* flagged, int64_t num_flagged, double feature_angle, FeatureLayout& layout) {
  const int32_t num_edges = mesh.num_edges();
  if (face_region && face_region_count != mesh.report().input_triangles)
    throw std::invalid_argument("face regions have " + std::to_string(face_region_count) +
                                " entries, but the mesh has " + std::to_string(mesh.report().input_triangles) +
                                " triangles");
  // A closed manifold mesh without regions, flagged edges or creases has no feature edge: the
  // mesh then need not build its edge tables for this.
  if (!face_region && num_flagged == 0 && feature_angle <= 0 && mesh.report().boundary_edges == 0 &&
      mesh.report().nonmanifold_edges == 0)
    return;
  layout.edge_feature.assign(num_edges, 0);
  const auto& efo = mesh.edge_face_offsets();
  // The faces of each edge only where regions or creases are compared across edges.
  const int32_t* ef = face_region || feature_angle > 0 ? mesh.edge_faces().data() : nullptr;
  const auto& source = mesh.face_source();
  layout.region_border_edges = parallel_sum<int32_t>(0, num_edges, kParallelMin, [&](int32_t& region_borders, int32_t e) {
    const int32_t k = efo[e + 1] - efo[e];
    if (k != 2) {
      layout.edge_feature[e] = 1;  // boundary or non-manifold
    } else if (face_region && face_region[source[ef[efo[e]]]] != face_region[source[ef[efo[e] + 1]]]) {
      layout.edge_feature[e] = 1;
      ++region_borders;
    }
  });
  for (int64_t i = 0; i < num_flagged; ++i) {
    const int32_t a = flagged[2 * i], b = flagged[2 * i + 1];
    const int32_t n = mesh.num_vertices();
    const bool in_range = a >= 0 && a < n && b >= 0 && b < n;
    const int32_t e = in_range ? mesh.find_edge(mesh.vertex_index()[a], mesh.vertex_index()[b]) : -1;
    if (e < 0)
      throw std::invalid_argument("border edge " + std::to_string(i) + " (" + std::to_string(a) + ", " +
                                  std::to_string(b) + ") is not an edge of the mesh");
    if (!layout.edge_feature[e]) ++layout.flagged_edges;
    layout.edge_feature[e] = 1;
  }
  if (feature_angle > 0) {
    // Creases: the angle between the two triangles' normals exceeds the feature angle.
    const double threshold = std::cos(feature_angle);
    const auto& faces = mesh.faces();
    auto unit_normal = [&](int32_t f, double* n) {
      const double* a = mesh.position(faces[3 * size_t(f)]);
      const double* b = mesh.position(faces[3 * size_t(f) + 1]);
      const double* c = mesh.position(faces[3 * size_t(f) + 2]);
      const double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]}, w[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
      n[0] = u[1] * w[2] - u[2] * w[1], n[1] = u[2] * w[0] - u[0] * w[2], n[2] = u[0] * w[1] - u[1] * w[0];
      const double len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
      if (len == 0) return false;
      n[0] /= len, n[1] /= len, n[2] /= len;
      return true;
    };
    layout.crease_edges = parallel_sum<int32_t>(0, num_edges, kParallelMin, [&](int32_t& creases, int32_t e) {
      if (layout.edge_feature[e] || efo[e + 1] - efo[e] != 2) return;
      double n0[3], n1[3];
      if (!unit_normal(ef[efo[e]], n0) || !unit_normal(ef[efo[e] + 1], n1)) return;
      if (n0[0] * n1[0] + n0[1] * n1[1] + n0[2] * n1[2] < threshold) {
        layout.edge_feature[e] = 1;
        ++creases;
      }
    });
  }
  for (int32_t e = 0; e < num_edges; ++e)
    if (layout.edge_feature[e]) layout.feature_edges.push_back(e);
  if (layout.feature_edges.empty()) std::vector<uint8_t>().swap(layout.edge_feature);  // all zero: is_feature_edge
}

// FeatureLayout::loose_vertices: found once with the layout, not on every draw of a slider.
std::vector<int32_t> loose_triangle_vertices(const Mesh& mesh) {
  std::vector<int32_t> loose;
  if (!mesh.many_pieces()) return loose;
  const auto& faces = mesh.faces();
  for (int32_t f = 0; f < mesh.num_faces(); ++f)
    if (mesh.loose_face(f)) loose.insert(loose.end(), &faces[3 * size_t(f)], &faces[3 * size_t(f)] + 3);
  std::sort(loose.begin(), loose.end());
  return loose;
}

// Whether face f has area: its cross product is not zero (the rule Mesh's report counts by).
bool has_area(const Mesh& mesh, int32_t f) {
  const int32_t* q = &mesh.faces()[3 * size_t(f)];
  const double *a = mesh.position(q[0]), *b = mesh.position(q[1]), *c = mesh.position(q[2]);
  const double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]}, w[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
  return u[1] * w[2] - u[2] * w[1] != 0.0 || u[2] * w[0] - u[0] * w[2] != 0.0 || u[0] * w[1] - u[1] * w[0] != 0.0;
}

// Whether every face around v has area: a seam corner there never holds a zero-area triangle
// the clean-up must collapse (coincident vertices: the spider of tests/data).
bool star_has_area(const Mesh& mesh, int32_t v) {
  bool all = true;
  mesh.for_each_face(v, [&](int32_t f) { all = all && has_area(mesh, f); });
  return all;
}

// FeatureLayout::winding_seam_vertices: per component, the lowest edge whose two triangles run
// along it the same way, with no zero-area triangle around their corners (one must be able to
// go), and those triangles' corners.
std::vector<int32_t> winding_seam_vertices(const Mesh& mesh) {
  std::vector<int32_t> seam;
  if (mesh.report().inconsistent_edges == 0) return seam;
  std::vector<uint8_t> done(size_t(mesh.report().components) + 1, 0);
  const auto& faces = mesh.faces();
  for (int32_t e = 0; e < mesh.num_edges(); ++e) {
    if (mesh.edge_face_count(e) != 2) continue;
    const int32_t component = mesh.component()[mesh.edge_vertices()[2 * size_t(e)]];
    if (component < 0 || done[size_t(component)]) continue;
    const int32_t o = mesh.edge_face_offsets()[e], f = mesh.edge_faces()[o], g = mesh.edge_faces()[o + 1];
    if (mesh.runs_forward(f, e) != mesh.runs_forward(g, e)) continue;  // consistent
    bool clean = true;
    for (int32_t h : {f, g})
      for (int j = 0; j < 3; ++j) clean = clean && star_has_area(mesh, faces[3 * size_t(h) + j]);
    if (!clean) continue;
    done[size_t(component)] = 1;
    seam.insert(seam.end(), &faces[3 * size_t(f)], &faces[3 * size_t(f)] + 3);
    seam.insert(seam.end(), &faces[3 * size_t(g)], &faces[3 * size_t(g)] + 3);
  }
  std::sort(seam.begin(), seam.end());
  seam.erase(std::unique(seam.begin(), seam.end()), seam.end());
  return seam;
}

// The sectors of the faces around the vertices of more than one sector (FeatureLayout::
// sector_of_slot) that one thread's run of vertices found, in vertex order.
struct SectorSlots {
  std::vector<int32_t> vertex, count, sector;
  void add(int32_t v, const std::vector<int32_t>& fan_of_slot) {
    vertex.push_back(v);
    count.push_back(int32_t(fan_of_slot.size()));
    sector.insert(sector.end(), fan_of_slot.begin(), fan_of_slot.end());
  }
};

// Every thread's slots into the layout, in thread order (the static runs' order: by vertex).
void record_sector_slots(PerThread<SectorSlots>& found, FeatureLayout& layout) {
  layout.sector_slot_vertex.clear(), layout.sector_slot_offsets.assign(1, 0), layout.sector_of_slot.clear();
  for (int t = 0; t < found.size(); ++t) {
    const SectorSlots& run = found[t];
    layout.sector_slot_vertex.insert(layout.sector_slot_vertex.end(), run.vertex.begin(), run.vertex.end());
    for (int32_t c : run.count) layout.sector_slot_offsets.push_back(layout.sector_slot_offsets.back() + c);
    layout.sector_of_slot.insert(layout.sector_of_slot.end(), run.sector.begin(), run.sector.end());
  }
}

void compute_sectors_and_corners(const Mesh& mesh, FeatureLayout& layout) {
  const int32_t n = mesh.num_vertices();
  const auto& ao = mesh.adjacency_offsets();
  const bool featureless = layout.feature_edges.empty();  // every edge one copy, none a feature
  const int32_t* ae = featureless ? nullptr : mesh.adjacency_edge().data();
  layout.feature_degree.clear();
  layout.sectors.clear(), layout.vertex_feature.clear(), layout.vertex_corner.clear();
  const auto& manifold = mesh.manifold_vertex();
  if (featureless && parallel_count<int32_t>(0, n, kParallelMin, [&](int32_t v) {
        return mesh.in_faces(v) && !manifold[v];
      }) == 0)
    return;  // one sector per vertex in faces, no feature vertex, no corner: the tables stay empty
  if (!featureless) layout.feature_degree.assign(n, 0);
  // Sectors per face slot matter only where a vertex has more than one (see sector_of).
  const auto& report = mesh.report();
  // Where every feature edge is a boundary edge and every vertex manifold, each vertex's faces
  // are one fan (a boundary edge joins no two faces): one sector each, no fans to find, and each
  // edge one copy, so sectors_of and chi_of need no tables either.
  const bool borders_only = report.nonmanifold_vertices == 0 && report.nonmanifold_edges == 0 &&
                            report.inconsistent_edges == 0 && layout.region_border_edges == 0 &&
                            layout.flagged_edges == 0 && layout.crease_edges == 0;
  if (!borders_only) layout.sectors.assign(n, 0);
  layout.vertex_feature.assign(n, 0);
  layout.vertex_corner.assign(n, 0);
  // Without feature edges chi_of computes the constant (n integers fewer on a large scan).
  layout.chi_constant.clear();
  if (!featureless && !borders_only) layout.chi_constant.assign(n, 0);
  PerThread<SectorSlots> found(max_threads());
  parallel_region(team_for(n, kParallelMin), [&](Team& team) {
    std::vector<int32_t> fan_of_slot;
    VertexStar star;
    team.for_static(0, n, [&](int32_t v) {
      if (!mesh.in_faces(v)) return;  // isolated: belongs to no cluster
      int32_t degree = 0, copies = featureless ? ao[v + 1] - ao[v] : 0, first_copies = -1;
      bool same_copies = true;
      for (int32_t i = ao[v]; i < ao[v + 1] && !featureless; ++i) {
        const int32_t e = ae[i];
        const int32_t c = layout.edge_copies(mesh, e);
        copies += c;
        if (layout.is_feature_edge(e)) {
          ++degree;
          if (first_copies < 0) first_copies = c;
          same_copies = same_copies && c == first_copies;
        }
      }
      // A manifold vertex without feature edges, or with boundary edges alone, is one sector;
      // others need the fans (the faces' sectors kept where there are several).
      int32_t sectors = 1;
      if (!borders_only && (degree > 0 || !mesh.manifold_vertex()[v])) {
        sectors = vertex_fans(mesh, v, [&](int32_t e) { return layout.is_feature_edge(e); }, fan_of_slot, star);
        if (sectors > 1) found.mine().add(v, fan_of_slot);
      }
      if (!featureless) layout.feature_degree[v] = degree;
      if (!borders_only) layout.sectors[v] = sectors;
      layout.vertex_feature[v] = degree > 0 || sectors > 1;
      // A curve vertex continues one curve: two feature edges of the same kind and one sector
      // per side. Everything else on a feature (ends, junctions, pinches) is a corner.
      const bool curve_vertex = degree == 2 && same_copies && sectors == first_copies;
      layout.vertex_corner[v] = layout.vertex_feature[v] && !curve_vertex;
      if (!featureless && !borders_only) layout.chi_constant[v] = 6 * sectors - 3 * copies + 2 * mesh.face_count(v);
    });
  });
  record_sector_slots(found, layout);
}

void trace_curves(const Mesh& mesh, FeatureLayout& layout) {
  const int32_t n = mesh.num_vertices();
  layout.vertex_curve.clear();
  if (layout.feature_edges.empty()) return;  // no curves (and no table of them: curve_of)
  layout.vertex_curve.assign(n, -1);
  const auto& ao = mesh.adjacency_offsets();
  const auto& adj = mesh.adjacency();
  const auto& ae = mesh.adjacency_edge();
  std::vector<uint8_t> visited(mesh.num_edges(), 0);
  // Next feature edge at curve vertex v other than the one we came by.
  auto step = [&](int32_t v, int32_t from_edge, int32_t& next_vertex, int32_t& next_edge) {
    for (int32_t i = ao[v]; i < ao[v + 1]; ++i)
      if (layout.edge_feature[ae[i]] && ae[i] != from_edge) {
        next_vertex = adj[i];
        next_edge = ae[i];
        return true;
      }
    return false;
  };
  auto walk = [&](int32_t start, int32_t first_vertex, int32_t first_edge, bool closed) {
    const int32_t curve = layout.num_curves();
    layout.curve_vertices.push_back(start);
    visited[first_edge] = 1;
    int32_t v = first_vertex, e = first_edge;
    while (v != start && !layout.vertex_corner[v]) {
      layout.curve_vertices.push_back(v);
      layout.vertex_curve[v] = curve;
      int32_t nv = -1, ne = -1;
      if (!step(v, e, nv, ne)) break;
      visited[ne] = 1;
      v = nv;
      e = ne;
    }
    if (!closed) layout.curve_vertices.push_back(v);  // the end corner
    if (closed) layout.vertex_curve[start] = curve;
    layout.curve_offsets.push_back(static_cast<int32_t>(layout.curve_vertices.size()));
    layout.curve_closed.push_back(closed ? 1 : 0);
  };
  // Open segments start at corners, in vertex order.
  for (int32_t c = 0; c < n; ++c) {
    if (!layout.vertex_corner[c]) continue;
    for (int32_t i = ao[c]; i < ao[c + 1]; ++i)
      if (layout.edge_feature[ae[i]] && !visited[ae[i]]) walk(c, adj[i], ae[i], false);
  }
  // What remains are closed loops of curve vertices.
  for (int32_t v = 0; v < n; ++v) {
    if (!layout.vertex_feature[v] || layout.vertex_corner[v] || layout.vertex_curve[v] >= 0) continue;
    for (int32_t i = ao[v]; i < ao[v + 1]; ++i)
      if (layout.edge_feature[ae[i]] && !visited[ae[i]]) {
        walk(v, adj[i], ae[i], true);
        break;
      }
  }
}

// Boundary loops as cycles of boundary edges. At a vertex the two boundary edges of one fan
// continue each other; at a pinched vertex (several open fans) each fan's pair is its own
// passage, so a hole whose rim runs through a pinch stays a loop of its own. (Joining every
// boundary edge at a shared vertex merged that hole with the other wing's rim: the merged loop
// met three clusters while the hole met two and closed up, with nothing local to split.)
void collect_boundary_loops(const Mesh& mesh, FeatureLayout& layout) {
  if (mesh.report().boundary_edges == 0) return;
  const int32_t n = mesh.num_vertices();
  const auto& ev = mesh.edge_vertices();
  const auto& ao = mesh.adjacency_offsets();
  const auto& ae = mesh.adjacency_edge();
  std::vector<int32_t> boundary_edges;
  for (int32_t e = 0; e < mesh.num_edges(); ++e)
    if (mesh.edge_face_count(e) == 1) boundary_edges.push_back(e);
  if (boundary_edges.empty()) return;
  std::vector<int32_t> slot_of(mesh.num_edges(), -1);  // boundary edge -> index in boundary_edges
  for (size_t i = 0; i < boundary_edges.size(); ++i) slot_of[boundary_edges[i]] = int32_t(i);
  std::vector<int32_t> parent(boundary_edges.size());
  for (size_t i = 0; i < parent.size(); ++i) parent[i] = int32_t(i);
  auto find = [&](int32_t x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  };
  auto unite = [&](int32_t a, int32_t b) {
    const int32_t ra = find(a), rb = find(b);
    if (ra != rb) parent[std::max(ra, rb)] = std::min(ra, rb);
  };
  std::vector<int32_t> fan_of_slot, at_vertex, fan_of_edge;
  VertexStar star;
  for (int32_t v = 0; v < n; ++v) {
    at_vertex.clear();
    for (int32_t i = ao[v]; i < ao[v + 1]; ++i)
      if (slot_of[ae[i]] >= 0) at_vertex.push_back(ae[i]);
    if (at_vertex.size() < 2) continue;
    if (mesh.manifold_vertex()[v]) {  // one fan: its two boundary edges
      for (size_t k = 1; k < at_vertex.size(); ++k) unite(slot_of[at_vertex[0]], slot_of[at_vertex[k]]);
      continue;
    }
    vertex_fans(mesh, v, [](int32_t) { return false; }, fan_of_slot, star);
    fan_of_edge.clear();
    for (int32_t e : at_vertex) {  // the fan of the edge's one face (v's face holding its other end)
      const int32_t w = ev[2 * size_t(e)] == v ? ev[2 * size_t(e) + 1] : ev[2 * size_t(e)];
      int32_t fan = -1;
      for (int32_t i = 0; i < star.size(); ++i)
        if (star.next[i] == w || star.prev[i] == w) fan = fan_of_slot[i];
      fan_of_edge.push_back(fan);
    }
    for (size_t k = 0; k < at_vertex.size(); ++k)
      for (size_t j = 0; j < k; ++j)
        if (fan_of_edge[j] == fan_of_edge[k]) unite(slot_of[at_vertex[j]], slot_of[at_vertex[k]]);
  }
  // Loops in order of their lowest edge (so of their lowest vertex on manifold meshes), each
  // as the set of its vertices.
  std::vector<int32_t> loop_of(boundary_edges.size(), -1);
  int32_t loops = 0;
  for (size_t i = 0; i < boundary_edges.size(); ++i)
    if (find(int32_t(i)) == int32_t(i)) loop_of[i] = loops++;
  std::vector<std::vector<int32_t>> vertices(loops);
  for (size_t i = 0; i < boundary_edges.size(); ++i) {
    auto& list = vertices[loop_of[find(int32_t(i))]];
    list.push_back(ev[2 * size_t(boundary_edges[i])]);
    list.push_back(ev[2 * size_t(boundary_edges[i]) + 1]);
  }
  layout.boundary_loop_offsets.assign(1, 0);
  layout.boundary_loop_vertices.clear();
  for (auto& list : vertices) {
    std::sort(list.begin(), list.end());
    list.erase(std::unique(list.begin(), list.end()), list.end());
    layout.boundary_loop_vertices.insert(layout.boundary_loop_vertices.end(), list.begin(), list.end());
    layout.boundary_loop_offsets.push_back(int32_t(layout.boundary_loop_vertices.size()));
  }
}

}  // namespace

std::shared_ptr<const FeatureLayout> build_feature_layout(const Mesh& mesh, const int32_t* face_region,
                                                          int64_t face_region_count, const int32_t* flagged_edges,
                                                          int64_t num_flagged_edges, double feature_angle) {
  if (!(feature_angle >= 0.0 && feature_angle <= kPi))
    throw std::invalid_argument("feature angle must lie in [0, pi] radians");
  auto layout = std::make_shared<FeatureLayout>();
  mark_feature_edges(mesh, face_region, face_region_count, flagged_edges, num_flagged_edges, feature_angle, *layout);
  compute_sectors_and_corners(mesh, *layout);
  layout->num_vertices = mesh.num_vertices();
  layout->num_edges = mesh.num_edges();
  layout->has_feature_vertices =
      std::find(layout->vertex_feature.begin(), layout->vertex_feature.end(), 1) != layout->vertex_feature.end();
  trace_curves(mesh, *layout);
  layout->curve_bends = find_curve_bends(mesh, *layout);
  layout->loose_vertices = loose_triangle_vertices(mesh);
  layout->winding_seam_vertices = winding_seam_vertices(mesh);
  collect_boundary_loops(mesh, *layout);
  PinchedVertices pinched = find_pinched_vertices(mesh);
  if (pinched.count > 0) {
    layout->vertex_pinched = std::move(pinched.pinched);
    layout->face_sheet = face_sheets(mesh);
  }
  return layout;
}

}  // namespace topstoc
