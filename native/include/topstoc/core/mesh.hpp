// Prepared triangle mesh: validated input, adjacency, normals and importance weights.
//
// Built once per mesh state and shared by every decimation, measurement and analysis call, so
// that re-decimating while a slider moves costs milliseconds. Construction validates the input:
// non-finite coordinates and out-of-range indices raise std::invalid_argument (Python
// ValueError) naming the first offending element; degenerate triangles (a repeated vertex) and
// exact duplicates (the same three vertices in any order) are dropped and counted. The caller's
// arrays are copied, never modified.
//
// Internally vertices are renumbered along a Z-order (Morton) curve and faces by their lowest
// vertex, so that neighbours sit close in memory: on a 775k-vertex mesh stored in random order
// this makes a flood fill several times faster. Every accessor below uses the internal
// numbering; vertex_source() and face_source() map back to the caller's ids, vertex_index()
// maps the caller's vertex ids in.
#pragma once

#include <atomic>
#include <cstdint>
#include <mutex>
#include <string>
#include <vector>

#include "topstoc/core/serial.hpp"
#include "topstoc/core/buffer.hpp"
#include "topstoc/core/component_ids.hpp"
#include "topstoc/core/vertex_flags.hpp"
#include "topstoc/core/progress.hpp"

namespace topstoc {

/// What validation found and repaired. Counts refer to the caller's arrays.
struct MeshReport {
  int32_t input_vertices = 0;
  int32_t input_triangles = 0;
  int32_t degenerate_triangles = 0;   ///< repeated vertex index: dropped
  int32_t duplicate_triangles = 0;    ///< same vertex set as an earlier triangle: dropped
  int32_t zero_area_triangles = 0;    ///< distinct vertices, zero area: kept
  int32_t isolated_vertices = 0;      ///< in no kept triangle: never part of any output
  int32_t boundary_edges = 0;         ///< edges with one triangle
  int32_t nonmanifold_edges = 0;      ///< edges with three or more triangles
  int32_t nonmanifold_vertices = 0;   ///< pinched: several fans, no non-manifold edge
  int32_t inconsistent_edges = 0;     ///< two triangles traverse the edge in the same direction
  int32_t components = 0;             ///< connected components of the kept triangles
  std::vector<int32_t> dropped_triangles;  ///< input indices of dropped triangles
};

/// The slot of face f that holds its corner j in its component's consistent winding (flips:
/// Mesh::winding_flips(); a flipped face's second and third corners trade places).
inline int winding_slot(const std::vector<uint8_t>& flips, int32_t f, int j) {
  return flips.empty() || !flips[size_t(f)] || j == 0 ? j : 3 - j;
}

class Mesh {
 public:
  /// positions: 3n coordinates; triangles: 3m vertex indices. Throws std::invalid_argument.
  /// progress (optional) hears each preparation step; returning false stops the preparation
  /// with Cancelled (the live preview's Esc).
  Mesh(const std::vector<double>& positions, const int32_t* triangles, int64_t num_triangles,
       const ProgressCallback& progress = {});
  /// The same from the caller's buffers (read during construction only, never kept).
  Mesh(const double* positions, int64_t num_vertices, const int32_t* triangles, int64_t num_triangles,
       const ProgressCallback& progress = {});

  int32_t num_vertices() const { return num_vertices_; }
  int32_t num_faces() const { return static_cast<int32_t>(faces_.size() / 3); }
  int32_t num_edges() const { return num_edges_; }

  const double* position(int32_t v) const { return &positions_[3 * size_t(v)]; }
  const Buffer<double>& positions() const { return positions_; }
  /// Kept triangles (3 per face, corners in the caller's order) and each one's index in the
  /// caller's triangle array.
  const Buffer<int32_t>& faces() const { return faces_; }
  const Buffer<int32_t>& face_source() const { return face_source_; }
  /// Caller's id of each internal vertex, and internal id of each caller vertex. The second is
  /// the first's inverse: freed after the preparation, made again on first use, once (a
  /// one-off fast decimation reads it only after its peak).
  const Buffer<int32_t>& vertex_source() const { return vertex_source_; }
  const Buffer<int32_t>& vertex_index() const { return ensure_vertex_index(), vertex_index_; }
  /// The internal ids of a few caller vertex ids (a result's kept vertices), read off
  /// vertex_index() once it is made, else found by one scan of vertex_source() without making it.
  /// Throws std::out_of_range for an id outside the caller's vertices.
  std::vector<int32_t> internal_ids(const std::vector<int32_t>& caller_ids) const;
  /// The caller's triangle array as given (3 per triangle, dropped ones included), rebuilt from
  /// the kept faces and the dropped rows: a copy of the input need not be kept.
  std::vector<int32_t> caller_triangles() const;

  // Vertex adjacency, CSR with sorted neighbours; adjacency_edge gives the edge id of each slot.
  const Buffer<int32_t>& adjacency_offsets() const { return adjacency_offsets_; }
  const Buffer<int32_t>& adjacency() const { return adjacency_; }
  const Buffer<int32_t>& adjacency_edge() const { return ensure_edges(), adjacency_edge_; }
  /// Calls fn(f) for each face f around v, in increasing order. Faces are sorted by their
  /// lowest vertex, so v's faces are those of each lower neighbour's run that hold v, then v's
  /// own run: walked where read instead of a table of them (14 bytes a triangle).
  template <class Fn>
  void for_each_face(int32_t v, Fn&& fn) const;
  /// The faces around the vertices [a, b), each vertex's in increasing order, for per-vertex sums
  /// that make each face's term once: below(f, v) for each face of a run below a holding v (walked
  /// per vertex, as for_each_face), then own(f) once for each face of the runs of [a, b), whose
  /// corners are all at or above a.
  template <class Below, class Own>
  void for_block_faces(int32_t a, int32_t b, Below&& below, Own&& own) const {
    const int32_t below_a = lowest_offsets_[a];  // faces whose lowest vertex is below a
    for (int32_t v = a; v < b; ++v) walk_faces(v, [&](int32_t f) { return f >= below_a || (below(f, v), false); });
    for (int32_t f = below_a, end = lowest_offsets_[b]; f < end; ++f) own(f);
  }
  /// How many faces are around v, and the lowest of them (-1 for a vertex in no face).
  int32_t face_count(int32_t v) const;
  int32_t first_face(int32_t v) const;
  /// Whether face f is a piece of its own (no corner in another face), as an unwelded mesh's
  /// triangles are; and whether the mesh has pieces enough (more than a tenth of its faces) for
  /// such faces to be worth looking for.
  bool loose_face(int32_t f) const;
  bool many_pieces() const { return 10 * int64_t(report_.components) >= num_faces(); }
  /// Whether v is in a face (a vertex in a face has neighbours, an isolated one none).
  bool in_faces(int32_t v) const { return adjacency_offsets_[v + 1] > adjacency_offsets_[v]; }
  /// Faces around each vertex as a table (CSR, the same order as for_each_face), for code that
  /// numbers a vertex's face slots: freed after the preparation, made again on first use, once;
  /// kept from the preparation where the walk would cost more than kWalkPerFace reads a face.
  const Buffer<int32_t>& vertex_face_offsets() const { return ensure_vertex_faces(), vertex_face_offsets_; }
  const Buffer<int32_t>& vertex_faces() const { return ensure_vertex_faces(), vertex_faces_; }
  /// The caller's corner (3 x caller triangle + slot) of vertex v in its first face, -1 for a
  /// vertex in no face: where an output vertex with one side takes its attributes from.
  /// Looked up from the faces (a table of it was 4 bytes a vertex kept for a few reads).
  int32_t first_corner(int32_t v) const;
  // Edges (lower id first), the faces of each edge (CSR) and the edge of each face side. These
  // tables (about a third of the mesh's memory) are built on first use, once, whichever thread
  // asks: a decimation of a closed mesh without borders never needs them. The faces of each
  // edge and the edges of each face (24 bytes a triangle) are built apart, on their own first
  // use: the borders of a scan need the edges and their face counts only.
  const Buffer<int32_t>& edge_vertices() const { return ensure_edges(), edge_vertices_; }
  const Buffer<int32_t>& edge_face_offsets() const { return ensure_edges(), edge_face_offsets_; }
  const Buffer<int32_t>& edge_faces() const { return ensure_edge_faces(), edge_faces_; }
  /// face_edges[3f + c] is the edge from corner c to corner c+1 of face f.
  const Buffer<int32_t>& face_edges() const { return ensure_edge_faces(), face_edges_; }
  /// True when face f runs along its edge e from the edge's lower vertex to its higher one (two
  /// faces on an edge are wound consistently when they run along it opposite ways).
  bool runs_forward(int32_t f, int32_t e) const {
    for (int c = 0; c < 3; ++c)
      if (face_edges()[3 * size_t(f) + c] == e) return faces_[3 * size_t(f) + c] == edge_vertices()[2 * size_t(e)];
    return false;
  }
  int32_t edge_face_count(int32_t e) const {
    ensure_edges();
    return edge_face_offsets_[e + 1] - edge_face_offsets_[e];
  }
  /// Calls fn(f) for each face of edge e, in increasing order (edge_faces()' order), from that
  /// table where it is built, else from the lower end's faces: for code that reads a few edges.
  template <class Fn>
  void for_each_edge_face(int32_t e, Fn&& fn) const;
  /// Edge id between a and b, or -1.
  int32_t find_edge(int32_t a, int32_t b) const;

  /// Unit area-weighted vertex normals (zero for vertices without area). The preparation needs
  /// them for the weights only and frees them; they are computed again on first use, once.
  const Buffer<double>& normals() const { return ensure_normals(), normals_; }
  /// A third of the area of the triangles around each vertex, and its mean over vertices in
  /// faces. Computed on first use, once, whichever thread asks: only area-weighted sampling
  /// reads them.
  const Buffer<double>& vertex_areas() const { return ensure_vertex_areas(), vertex_areas_; }
  double mean_vertex_area() const { return ensure_vertex_areas(), mean_vertex_area_; }
  /// Importance weight x(v) of thesis eq. 4.1, in [0, 1]; mean over vertices in faces.
  const Buffer<double>& weights() const { return weights_; }
  double mean_weight() const { return mean_weight_; }
  /// Connected component of each vertex (-1 for isolated vertices), in as few bytes as the ids need.
  const ComponentIds& component() const { return component_; }
  int32_t num_components() const { return report_.components; }
  /// Euler characteristic V - E + F of each component.
  const Buffer<int64_t>& component_euler() const { return component_euler_; }
  /// True where the vertex's triangles form one consistently oriented fan and none of its
  /// edges is non-manifold.
  const VertexFlags& manifold_vertex() const { return manifold_vertex_; }
  /// Per face: 1 where it runs against a consistent orientation of its component (the component's
  /// first face sets it; faces meet across edges of two faces), else 0, and 0 on every face of a
  /// component that has none (a Moebius band). Empty when no edge is inconsistently oriented.
  /// What a decimation emits its triangles by, so that it need not keep the input's flipped
  /// patches apart; the output takes each triangle's winding back from its source face. Made on
  /// first use, once.
  const std::vector<uint8_t>& winding_flips() const {
    std::call_once(winding_once_, [this] { build_winding_flips(); });
    return winding_flips_;
  }
  /// Length of the bounding box diagonal.
  double diagonal() const { return diagonal_; }

  const MeshReport& report() const { return report_; }
  /// A number no other Mesh of this process has (what caches tell meshes apart by).
  uint64_t serial() const { return serial_; }

 private:
  void validate_faces(const int32_t* triangles, int64_t num_triangles);
  void reorder_for_locality(const double* positions, const int32_t* triangles, const double* lo, const double* hi,
                            Progress& progress);
  void drop_duplicate_faces();
  void find_lowest_offsets();
  void fill_vertex_faces() const;
  void ensure_vertex_faces() const {
    if (!vertex_faces_built_.load(std::memory_order_acquire)) build_vertex_faces();
  }
  void build_vertex_faces() const;
  /// v's faces in increasing order until stop(f) returns true (for_each_face, first_face).
  template <class Stop>
  void walk_faces(int32_t v, Stop&& stop) const;
  void keep_vertex_faces_where_walks_cost();
  void build_winding_flips() const;
  static constexpr int64_t kWalkPerFace = 16;
  /// The one-ring pass: adjacency, normals, weights, manifoldness, components.
  void build_adjacency(Progress& progress);
  void ensure_vertex_index() const {
    if (!vertex_index_built_.load(std::memory_order_acquire)) build_vertex_index();
  }
  void build_vertex_index() const;
  void ensure_edges() const {
    if (!edges_built_.load(std::memory_order_acquire)) build_edges();
  }
  void build_edges() const;
  void ensure_edge_faces() const {
    if (!edge_faces_built_.load(std::memory_order_acquire)) build_edge_faces();
  }
  void build_edge_faces() const;
  /// Per vertex its own slot in its sorted row (its lower neighbours first), and the id of its
  /// first edge (edges are numbered by lower end, then higher end; n + 1 entries).
  void edge_numbering(Buffer<int32_t>& lower, Buffer<int32_t>& edge_base) const;
  void ensure_normals() const {
    if (!normals_built_.load(std::memory_order_acquire)) build_normals();
  }
  void build_normals() const;
  void fill_normals() const;
  /// The unit area-weighted normal of v, as normals() holds it.
  void normal_at(int32_t v, double* out) const;
  /// The sums normal_at normalises, of the vertices [a, b), into sums (3 a vertex).
  void normal_sums(int32_t a, int32_t b, std::vector<double>& sums) const;
  /// The importance weights from the normals, computed a window of vertices at a time.
  void weigh();
  void ensure_vertex_areas() const {
    if (!areas_built_.load(std::memory_order_acquire)) build_vertex_areas();
  }
  void build_vertex_areas() const;

  uint64_t serial_ = new_serial();
  int32_t num_vertices_ = 0;
  Buffer<double> positions_;
  Buffer<int32_t> faces_, face_source_, vertex_source_;
  // Built on first use (ensure_vertex_index).
  mutable Buffer<int32_t> vertex_index_;
  mutable std::once_flag vertex_index_once_;
  mutable std::atomic<bool> vertex_index_built_{false};
  // Faces f with lowest vertex v: [lowest_offsets_[v], lowest_offsets_[v + 1]).
  Buffer<int32_t> lowest_offsets_;
  // Built for the one-ring pass, freed after it, built again on first use (ensure_vertex_faces).
  mutable Buffer<int32_t> vertex_face_offsets_, vertex_faces_;
  mutable std::once_flag vertex_faces_once_;
  mutable std::atomic<bool> vertex_faces_built_{false};
  Buffer<int32_t> adjacency_offsets_, adjacency_;
  int32_t num_edges_ = 0;
  // Built on first use (ensure_edges).
  mutable Buffer<int32_t> adjacency_edge_, edge_vertices_, edge_face_offsets_, edge_faces_, face_edges_;
  mutable std::once_flag edges_once_;
  mutable std::atomic<bool> edges_built_{false};
  mutable std::once_flag edge_faces_once_;
  mutable std::atomic<bool> edge_faces_built_{false};
  Buffer<double> weights_;
  // Built in the preparation, freed after it, built again on first use (ensure_normals).
  mutable std::vector<uint8_t> winding_flips_;
  mutable std::once_flag winding_once_;
  mutable Buffer<double> normals_;
  mutable std::once_flag normals_once_;
  mutable std::atomic<bool> normals_built_{false};
  double mean_weight_ = 0.0, diagonal_ = 0.0;
  // Built on first use (ensure_vertex_areas).
  mutable Buffer<double> vertex_areas_;
  mutable double mean_vertex_area_ = 0.0;
  mutable std::once_flag areas_once_;
  mutable std::atomic<bool> areas_built_{false};
  ComponentIds component_;
  Buffer<int64_t> component_euler_;
  VertexFlags manifold_vertex_;
  MeshReport report_;
  Buffer<int32_t> dropped_rows_;  ///< the caller's corners of each dropped triangle, in report order
};

template <class Stop>
void Mesh::walk_faces(int32_t v, Stop&& stop) const {
  if (vertex_faces_built_.load(std::memory_order_acquire)) {  // the table, where one is kept
    for (int32_t i = vertex_face_offsets_[v], end = vertex_face_offsets_[v + 1]; i < end; ++i)
      if (stop(vertex_faces_[i])) return;
    return;
  }
  const int32_t* row = adjacency_.data() + adjacency_offsets_[v];
  const int32_t* row_end = adjacency_.data() + adjacency_offsets_[v + 1];
  const int32_t* faces = faces_.data();
  for (; row != row_end && *row < v; ++row)  // the lower neighbours, in increasing order
    for (int32_t f = lowest_offsets_[*row], end = lowest_offsets_[*row + 1]; f < end; ++f) {
      const int32_t* t = faces + 3 * size_t(f);
      if ((t[1] == v || t[2] == v || t[0] == v) && stop(f)) return;
    }
  for (int32_t f = lowest_offsets_[v], end = lowest_offsets_[v + 1]; f < end; ++f)
    if (stop(f)) return;
}

template <class Fn>
void Mesh::for_each_face(int32_t v, Fn&& fn) const {
  walk_faces(v, [&](int32_t f) { return fn(f), false; });
}

template <class Fn>
void Mesh::for_each_edge_face(int32_t e, Fn&& fn) const {
  ensure_edges();
  if (edge_faces_built_.load(std::memory_order_acquire)) {
    for (int32_t i = edge_face_offsets_[e], end = edge_face_offsets_[e + 1]; i < end; ++i) fn(edge_faces_[i]);
    return;
  }
  const int32_t a = edge_vertices_[2 * size_t(e)], b = edge_vertices_[2 * size_t(e) + 1];
  for_each_face(a, [&](int32_t f) {
    const int32_t* t = &faces_[3 * size_t(f)];
    if (t[0] == b || t[1] == b || t[2] == b) fn(f);
  });
}

}  // namespace topstoc
