#include "topology/persistence.hpp"

#include <algorithm>
#include <stdexcept>

// PHAT is header-only and not written for -Wextra.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-parameter"
#pragma GCC diagnostic ignored "-Wsign-compare"
#include <phat/boundary_matrix.h>
#include <phat/representations/default_representations.h>
#pragma GCC diagnostic pop

namespace topstoc {

namespace {

enum Part : uint8_t { kSurface = 0, kInside = 1, kOutside = 2, kUnset = 3 };

uint64_t edge_key(int32_t a, int32_t b) {
  if (a > b) std::swap(a, b);
  return (uint64_t(uint32_t(a)) << 32) | uint32_t(b);
}

// Column numbers of the filtration: surface vertices, edges, faces; then per part (inside,
// outside) its vertices, edges, faces, tetrahedra.
struct Filtration {
  std::vector<int64_t> point_column, edge_column, face_column, tet_column;
  int64_t columns = 0;
  int64_t surface_edges_begin = 0, surface_edges_end = 0;
};

// The boundary matrix of one filtration, with each column's dimension and simplex.
struct FiltrationMatrix {
  phat::boundary_matrix<phat::bit_tree_pivot_column> matrix;
  std::vector<int8_t> dim;
  std::vector<int64_t> column_face, column_tet;
};

// One run of handle_tunnel_cycles: every simplex's part (surface, inside, outside), then per
// part a filtration, its reduction and the surface cycles it kills.
class PersistenceRun {
 public:
  PersistenceRun(const ClosedSurface& s, const TetMesh& t, Progress* progress)
      : s(s), t(t), progress(progress), num_points(t.num_points()), num_tets(t.num_tets()), num_faces(t.num_faces()),
        nv(s.num_vertices()) {}

  std::vector<PersistentCycle> run() {
    if (t.num_surface_points != nv) throw std::logic_error("tetrahedralization does not match the surface");
    label_parts();
    // Two filtrations: the surface then the inside (its dying cycles bound inside: handles),
    // and the surface then the outside (tunnels). A single filtration surface < inside <
    // outside would pair the right generator edges, but a tunnel cycle could then bound a
    // chain that also uses inside triangles, i.e. carry a handle component.
    for (uint8_t part : {kInside, kOutside}) {
      if (progress) progress->update(part == kInside ? 0.0 : 0.5);
      const Filtration fl = filtration(part);
      FiltrationMatrix m;
      build_matrix(fl, m);
      reduce(part, fl, m);
      collect_cycles(part, fl, m);
    }
    const int32_t g = s.genus();
    int32_t handles = 0;
    for (const auto& c : cycles) handles += c.handle;
    if (handles != g || int32_t(cycles.size()) - handles != g)
      throw std::logic_error("persistence found " + std::to_string(handles) + " handle and " +
                             std::to_string(cycles.size() - handles) + " tunnel cycles on a genus-" +
                             std::to_string(g) + " surface");
    return std::move(cycles);
  }

 private:
  const ClosedSurface& s;
  const TetMesh& t;
  Progress* progress;
  const int32_t num_points, num_tets, num_faces, nv;
  int32_t num_edges = 0;
  std::vector<uint8_t> point_part, face_part, edge_part;
  std::vector<uint64_t> edge_keys;       // every edge of the tetrahedra, sorted
  std::vector<int32_t> surface_edge_of;  // per edge: its surface edge, or -1
  std::vector<PersistentCycle> cycles;

  int32_t edge_id(int32_t a, int32_t b) const {
    return int32_t(std::lower_bound(edge_keys.begin(), edge_keys.end(), edge_key(a, b)) - edge_keys.begin());
  }
  uint8_t tet_part(int32_t k) const { return t.inside[k] ? kInside : kOutside; }

  // Part of every simplex: surface if on the surface, else the side of its tetrahedra.
  void label_parts() {
    point_part.assign(num_points, kUnset);
    face_part.assign(num_faces, kUnset);
    for (int32_t v = 0; v < nv; ++v) point_part[v] = kSurface;
    for (int32_t f : t.surface_face) face_part[f] = kSurface;
    edge_keys.reserve(6 * size_t(num_tets));
    for (int32_t k = 0; k < num_tets; ++k) {
      const uint8_t part = tet_part(k);
      const int32_t* c = &t.tets[4 * size_t(k)];
      for (int i = 0; i < 4; ++i) {
        if (point_part[c[i]] == kUnset) point_part[c[i]] = part;
        if (face_part[t.tet_faces[4 * size_t(k) + i]] == kUnset) face_part[t.tet_faces[4 * size_t(k) + i]] = part;
        for (int j = i + 1; j < 4; ++j) edge_keys.push_back(edge_key(c[i], c[j]));
      }
    }
    std::sort(edge_keys.begin(), edge_keys.end());
    edge_keys.erase(std::unique(edge_keys.begin(), edge_keys.end()), edge_keys.end());
    num_edges = int32_t(edge_keys.size());
    edge_part.assign(num_edges, kUnset);
    surface_edge_of.assign(num_edges, -1);
    for (int32_t e = 0; e < s.num_edges(); ++e) {
      const int32_t id = edge_id(s.edge_vertices[2 * size_t(e)], s.edge_vertices[2 * size_t(e) + 1]);
      edge_part[id] = kSurface;
      surface_edge_of[id] = e;
    }
    for (int32_t k = 0; k < num_tets; ++k) {
      const int32_t* c = &t.tets[4 * size_t(k)];
      for (int i = 0; i < 4; ++i)
        for (int j = i + 1; j < 4; ++j) {
          uint8_t& p = edge_part[edge_id(c[i], c[j])];
          if (p == kUnset) p = tet_part(k);
        }
    }
  }

  // Filtration order: the surface, then the part, by dimension.
  Filtration filtration(uint8_t part) const {
    Filtration fl;
    fl.point_column.assign(num_points, -1);
    fl.edge_column.assign(num_edges, -1);
    fl.face_column.assign(num_faces, -1);
    fl.tet_column.assign(num_tets, -1);
    for (int32_t v = 0; v < nv; ++v) fl.point_column[v] = fl.columns++;
    fl.surface_edges_begin = fl.columns;
    for (int32_t e = 0; e < s.num_edges(); ++e)
      fl.edge_column[edge_id(s.edge_vertices[2 * size_t(e)], s.edge_vertices[2 * size_t(e) + 1])] = fl.columns++;
    fl.surface_edges_end = fl.columns;
    for (int32_t f : t.surface_face) fl.face_column[f] = fl.columns++;
    for (int32_t q = 0; q < num_points; ++q)
      if (point_part[q] == part) fl.point_column[q] = fl.columns++;
    for (int32_t e = 0; e < num_edges; ++e)
      if (edge_part[e] == part) fl.edge_column[e] = fl.columns++;
    for (int32_t f = 0; f < num_faces; ++f)
      if (face_part[f] == part) fl.face_column[f] = fl.columns++;
    for (int32_t k = 0; k < num_tets; ++k)
      if (tet_part(k) == part) fl.tet_column[k] = fl.columns++;
    return fl;
  }

  // Boundary matrix: only triangles and tetrahedra matter for which surface cycles die, so
  // vertex and edge columns stay empty (edges are never reduced).
  void build_matrix(const Filtration& fl, FiltrationMatrix& m) const {
    m.matrix.set_num_cols(fl.columns);
    m.dim.assign(fl.columns, 0);
    m.column_face.assign(fl.columns, -1);
    m.column_tet.assign(fl.columns, -1);
    for (int32_t e = 0; e < num_edges; ++e)
      if (fl.edge_column[e] >= 0) m.dim[fl.edge_column[e]] = 1;
    for (int32_t f = 0; f < num_faces; ++f)
      if (fl.face_column[f] >= 0) {
        m.dim[fl.face_column[f]] = 2;
        m.column_face[fl.face_column[f]] = f;
      }
    for (int32_t k = 0; k < num_tets; ++k)
      if (fl.tet_column[k] >= 0) {
        m.dim[fl.tet_column[k]] = 3;
        m.column_tet[fl.tet_column[k]] = k;
      }
    std::vector<phat::index> column;
    for (int64_t c = 0; c < fl.columns; ++c) {
      m.matrix.set_dim(c, m.dim[c]);
      column.clear();
      if (m.dim[c] == 2) {
        const int32_t* v = &t.faces[3 * size_t(m.column_face[c])];
        column = {fl.edge_column[edge_id(v[0], v[1])], fl.edge_column[edge_id(v[0], v[2])],
                  fl.edge_column[edge_id(v[1], v[2])]};
      } else if (m.dim[c] == 3) {
        for (int i = 0; i < 4; ++i) column.push_back(fl.face_column[t.tet_faces[4 * size_t(m.column_tet[c]) + i]]);
      }
      for (phat::index row : column)
        if (row < 0) throw std::logic_error("a simplex's face is missing from the filtration");
      std::sort(column.begin(), column.end());
      if (!column.empty()) m.matrix.set_col(c, column);
    }
  }

  // Twist reduction (Chen & Kerber 2011) of the tetrahedra, then the triangles: a column whose
  // pivot is taken gets cleared, as it is positive.
  void reduce(uint8_t part, const Filtration& fl, FiltrationMatrix& m) const {
    std::vector<int64_t> owner_of_low(fl.columns, -1);
    for (int8_t d : {int8_t(3), int8_t(2)}) {
      for (int64_t c = 0; c < fl.columns; ++c) {
        if (m.dim[c] != d) continue;
        if (progress && (c & 1023) == 0)
          progress->update((part == kInside ? 0.0 : 0.5) + (d == 3 ? 0.0 : 0.25) + 0.25 * double(c) / double(fl.columns));
        phat::index low = m.matrix.get_max_index(c);
        while (low != -1 && owner_of_low[low] != -1) {
          m.matrix.add_to(owner_of_low[low], c);
          low = m.matrix.get_max_index(c);
        }
        if (low != -1) {
          owner_of_low[low] = c;
          m.matrix.clear(low);
        }
        m.matrix.finalize(c);
      }
    }
  }

  // Triangles of the part whose pivot is a surface edge kill a surface cycle.
  void collect_cycles(uint8_t part, const Filtration& fl, FiltrationMatrix& m) {
    std::vector<int32_t> edge_of_column(fl.surface_edges_end - fl.surface_edges_begin, -1);
    for (int32_t e = 0; e < num_edges; ++e)
      if (surface_edge_of[e] >= 0) edge_of_column[fl.edge_column[e] - fl.surface_edges_begin] = surface_edge_of[e];
    std::vector<phat::index> column;
    for (int64_t c = 0; c < fl.columns; ++c) {
      if (m.dim[c] != 2 || face_part[m.column_face[c]] != part) continue;
      const phat::index low = m.matrix.get_max_index(c);
      if (low < fl.surface_edges_begin || low >= fl.surface_edges_end) continue;
      PersistentCycle cycle;
      cycle.handle = part == kInside;
      cycle.generator_edge = edge_of_column[low - fl.surface_edges_begin];
      column.clear();  // PHAT appends the pivot column to what `column` holds
      m.matrix.get_col(c, column);
      for (phat::index row : column) {
        if (row < fl.surface_edges_begin || row >= fl.surface_edges_end)
          throw std::logic_error("a handle or tunnel cycle left the surface");
        cycle.edges.push_back(edge_of_column[row - fl.surface_edges_begin]);
      }
      cycles.push_back(std::move(cycle));
    }
  }
};

}  // namespace

std::vector<PersistentCycle> handle_tunnel_cycles(const ClosedSurface& s, const TetMesh& t, Progress* progress) {
  return PersistenceRun(s, t, progress).run();
}

}  // namespace topstoc
