#include "pinched_fans.hpp"

#include <algorithm>
#include <array>

#include "../core/fans.hpp"
#include "../core/union_find.hpp"

namespace topstoc {

namespace {

constexpr int32_t kUnknownSheet = -1;   // an output sheet none of whose triangles names one input sheet
constexpr int32_t kMergedSheets = -2;   // an output sheet whose triangles lie on different input sheets

// Whether the two faces of v's star holding w (the two slots of a run of sides) traverse edge
// (v, w) in opposite directions: w follows v in one and precedes it in the other.
bool oriented_consistently(const VertexStar& star, int32_t a, int32_t b) {
  const auto& sides = star.sides;
  return (star.next[sides[a].second] == sides[a].first) != (star.next[sides[b].second] == sides[b].first);
}

// The fans of output vertex o from its triangles (ids into `triangles`), joined across the
// edges at o that exactly two of them share; empty when an edge at o has more than two.
std::vector<Fan> output_fans(int32_t o, const std::vector<int32_t>& around, const std::vector<int32_t>& triangles,
                             UnionFind& out_sheets, const std::vector<int32_t>& sheet_of_output_sheet) {
  struct Neighbour {
    int32_t id, count = 0, first = -1;  // first: index in `around` of a triangle containing it
  };
  std::vector<Neighbour> neighbours;
  UnionFind joined(static_cast<int32_t>(around.size()));
  for (int32_t i = 0; i < int32_t(around.size()); ++i) {
    const int32_t* c = &triangles[3 * size_t(around[i])];
    for (int j = 0; j < 3; ++j) {
      if (c[j] == o) continue;
      auto it = std::find_if(neighbours.begin(), neighbours.end(), [&](const Neighbour& n) { return n.id == c[j]; });
      if (it == neighbours.end()) {
        neighbours.push_back({c[j], 1, i});
      } else {
        ++it->count;
        joined.unite(it->first, i);
      }
    }
  }
  std::vector<Fan> fans;
  std::vector<int32_t> fan_of_root(around.size(), -1);
  for (int32_t i = 0; i < int32_t(around.size()); ++i) {
    const int32_t root = joined.find(i);
    if (fan_of_root[root] >= 0) continue;
    fan_of_root[root] = static_cast<int32_t>(fans.size());
    fans.push_back({sheet_of_output_sheet[out_sheets.find(around[i])], true});
  }
  for (const auto& n : neighbours) {
    if (n.count > 2) return {};
    if (n.count == 1) fans[fan_of_root[joined.find(n.first)]].closed = false;
  }
  return fans;
}

// Each output fan matches an input fan of the same kind on the same sheet (an output sheet
// that names no input sheet matches any sheet).
bool fans_match(std::vector<Fan> input, const std::vector<Fan>& output) {
  if (input.size() != output.size()) return false;
  std::vector<Fan> unknown;
  for (const Fan& f : output) {
    if (f.sheet == kMergedSheets) return false;
    if (f.sheet == kUnknownSheet) {
      unknown.push_back(f);
      continue;
    }
    auto it = std::find_if(input.begin(), input.end(),
                           [&](const Fan& g) { return g.sheet == f.sheet && g.closed == f.closed; });
    if (it == input.end()) return false;
    input.erase(it);
  }
  for (const Fan& f : unknown) {
    auto it = std::find_if(input.begin(), input.end(), [&](const Fan& g) { return g.closed == f.closed; });
    if (it == input.end()) return false;
    input.erase(it);
  }
  return true;
}

}  // namespace

std::vector<int32_t> face_sheets(const Mesh& mesh) {
  // Each edge (v, w) with exactly two faces joins them, read once at its lower end v.
  UnionFind sheets(mesh.num_faces());
  VertexStar star;
  for (int32_t v = 0; v < mesh.num_vertices(); ++v) {
    star.read(mesh, v);
    star.for_each_edge([&](int32_t w, int32_t first, int32_t faces) {
      if (faces == 2 && w > v) sheets.unite(star.faces[star.sides[first].second], star.faces[star.sides[first + 1].second]);
    });
  }
  std::vector<int32_t> sheet(mesh.num_faces());
  for (int32_t f = 0; f < mesh.num_faces(); ++f) sheet[f] = sheets.find(f);  // roots are the lowest faces
  return sheet;
}

std::vector<Fan> input_fans(const Mesh& mesh, const std::vector<int32_t>& face_sheet, int32_t v) {
  std::vector<int32_t> fan_of_slot;
  VertexStar star;
  const int32_t count = vertex_fans(mesh, v, [](int32_t) { return false; }, fan_of_slot, star);
  std::vector<Fan> fans(count, Fan{-1, true});
  for (int32_t i = 0; i < star.size(); ++i) {
    Fan& fan = fans[fan_of_slot[i]];
    fan.sheet = face_sheet[star.faces[i]];
    if (star.edge_faces(star.next[i]) == 1 || star.edge_faces(star.prev[i]) == 1) fan.closed = false;
  }
  return fans;
}

PinchedVertices find_pinched_vertices(const Mesh& mesh) {
  PinchedVertices out;
  if (mesh.report().nonmanifold_vertices == 0) return out;
  const int32_t n = mesh.num_vertices();
  out.pinched.assign(n, 0);
  std::vector<uint8_t> has_pinch(mesh.num_components(), 0), other_defect(mesh.num_components(), 0);
  std::vector<int32_t> fan_of_slot;
  VertexStar star;
  for (int32_t v = 0; v < n; ++v) {
    if (mesh.component()[v] < 0 || mesh.manifold_vertex()[v]) continue;
    // Every edge at v: one or two faces, two traversing it in opposite directions.
    star.read(mesh, v);
    bool clean_edges = true;
    star.for_each_edge([&](int32_t, int32_t first, int32_t faces) {
      clean_edges = clean_edges && faces <= 2 && (faces < 2 || oriented_consistently(star, first, first + 1));
    });
    if (clean_edges && fans_of_star(mesh, v, star, [](int32_t) { return false; }, fan_of_slot) >= 2) {
      out.pinched[v] = 1;
      ++out.count;
      has_pinch[mesh.component()[v]] = 1;
    } else {
      other_defect[mesh.component()[v]] = 1;
    }
  }
  out.pinched_surface.assign(mesh.num_components(), 0);
  for (int32_t c = 0; c < mesh.num_components(); ++c) out.pinched_surface[c] = has_pinch[c] && !other_defect[c];
  return out;
}

std::vector<int32_t> boundary_edge_groups(const Mesh& mesh) {
  const int32_t n = mesh.num_vertices();
  UnionFind groups(n);
  std::vector<uint8_t> on_boundary(n, 0);
  for (int32_t e = 0; e < mesh.num_edges(); ++e) {
    if (mesh.edge_face_count(e) != 1) continue;
    const int32_t a = mesh.edge_vertices()[2 * size_t(e)], b = mesh.edge_vertices()[2 * size_t(e) + 1];
    groups.unite(a, b);
    on_boundary[a] = on_boundary[b] = 1;
  }
  std::vector<int32_t> loops(mesh.num_components(), 0);
  for (int32_t v = 0; v < n; ++v)
    if (on_boundary[v] && groups.find(v) == v) ++loops[mesh.component()[v]];
  return loops;
}

int32_t changed_pinched_fans(const Mesh& mesh, const PinchedVertices& pinched, const std::vector<int32_t>& kept,
                             const std::vector<int32_t>& triangles) {
  if (pinched.count == 0) return 0;
  const int32_t t = static_cast<int32_t>(triangles.size() / 3);
  auto valid = [&](int32_t i) {
    const int32_t* c = &triangles[3 * size_t(i)];
    return c[0] != c[1] && c[1] != c[2] && c[2] != c[0];
  };
  const std::vector<int32_t> sheet = face_sheets(mesh);

  // Output sheets: triangles joined across edges that exactly two of them share.
  std::vector<std::array<int32_t, 3>> sides;  // lower end, upper end, triangle
  for (int32_t i = 0; i < t; ++i) {
    if (!valid(i)) continue;
    for (int j = 0; j < 3; ++j) {
      const int32_t a = triangles[3 * size_t(i) + j], b = triangles[3 * size_t(i) + (j + 1) % 3];
      sides.push_back({std::min(a, b), std::max(a, b), i});
    }
  }
  std::sort(sides.begin(), sides.end());
  UnionFind out_sheets(t);
  for (size_t i = 0; i < sides.size();) {
    size_t j = i;
    while (j < sides.size() && sides[j][0] == sides[i][0] && sides[j][1] == sides[i][1]) ++j;
    if (j - i == 2) out_sheets.unite(sides[i][2], sides[i + 1][2]);
    i = j;
  }

  // The input sheet of each output sheet: the one its triangles' corners have in common.
  auto sheets_of = [&](int32_t v, std::vector<int32_t>& into) {
    into.clear();
    mesh.for_each_face(v, [&](int32_t f) { into.push_back(sheet[f]); });
    std::sort(into.begin(), into.end());
    into.erase(std::unique(into.begin(), into.end()), into.end());
  };
  std::vector<int32_t> sheet_of_output_sheet(t, kUnknownSheet), common, next, corner;
  for (int32_t i = 0; i < t; ++i) {
    if (!valid(i)) continue;
    sheets_of(kept[triangles[3 * size_t(i)]], common);
    for (int j = 1; j < 3; ++j) {
      sheets_of(kept[triangles[3 * size_t(i) + j]], corner);
      next.clear();
      std::set_intersection(common.begin(), common.end(), corner.begin(), corner.end(), std::back_inserter(next));
      common.swap(next);
    }
    int32_t& mapped = sheet_of_output_sheet[out_sheets.find(i)];
    if (common.empty()) {
      mapped = kMergedSheets;  // a triangle across sheets the input only joins at vertices
    } else if (common.size() == 1 && mapped != kMergedSheets) {
      mapped = mapped == kUnknownSheet || mapped == common[0] ? common[0] : kMergedSheets;
    }
  }

  // Triangles around the output vertex of each pinched input vertex.
  std::vector<int32_t> output_of(mesh.num_vertices(), -1);
  for (int32_t o = 0; o < int32_t(kept.size()); ++o) output_of[kept[o]] = o;
  std::vector<int32_t> slot_of_output(kept.size(), -1);
  std::vector<int32_t> pinched_inputs;
  for (int32_t v = 0; v < mesh.num_vertices(); ++v) {
    if (!pinched.pinched[v]) continue;
    pinched_inputs.push_back(v);
    if (output_of[v] >= 0) slot_of_output[output_of[v]] = static_cast<int32_t>(pinched_inputs.size() - 1);
  }
  std::vector<std::vector<int32_t>> around(pinched_inputs.size());
  for (int32_t i = 0; i < t; ++i) {
    if (!valid(i)) continue;
    for (int j = 0; j < 3; ++j) {
      const int32_t slot = slot_of_output[triangles[3 * size_t(i) + j]];
      if (slot >= 0) around[slot].push_back(i);
    }
  }

  int32_t changed = 0;
  for (size_t k = 0; k < pinched_inputs.size(); ++k) {
    const int32_t v = pinched_inputs[k];
    const int32_t o = output_of[v];
    if (o < 0) {
      ++changed;  // the pinch is gone (pinched vertices are always kept)
      continue;
    }
    if (!fans_match(input_fans(mesh, sheet, v), output_fans(o, around[k], triangles, out_sheets, sheet_of_output_sheet)))
      ++changed;
  }
  return changed;
}

}  // namespace topstoc
