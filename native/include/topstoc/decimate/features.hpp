// Feature layout: the edges that no cluster may cross, and what follows from them.
//
// Feature edges are mesh boundary edges, non-manifold edges, borders between faces with
// different region ids (materials, UV islands), edges the caller flags (UV seams, sharp
// edges) and, on request, creases sharper than a feature angle. Cutting the mesh along them splits each vertex into sectors (fans of triangles);
// the decimation treats every sector as its own side of a border. Feature vertices are
// reached by the flood fill only along feature edges, so each border is sampled and
// partitioned as a curve of its own and survives into the output; corners (where curves
// meet or end, and pinched vertices) are always kept.
#pragma once

#include <cstdint>
#include <memory>
#include <mutex>
#include <vector>

#include "topstoc/core/serial.hpp"
#include "topstoc/core/mesh.hpp"

namespace topstoc {

/// One table another module derives from a layout and its mesh and keeps between calls
/// (sampling keeps its per-vertex importance there: a slider re-decimating with the same
/// parameters then skips recomputing it). Copies start empty; safe to use from many threads.
class DerivedTable {
 public:
  DerivedTable() = default;
  DerivedTable(const DerivedTable&) {}
  DerivedTable& operator=(const DerivedTable&) { return *this; }
  std::shared_ptr<const void> get() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return table_;
  }
  void set(std::shared_ptr<const void> table) const {
    std::lock_guard<std::mutex> lock(mutex_);
    table_ = std::move(table);
  }

 private:
  mutable std::mutex mutex_;
  mutable std::shared_ptr<const void> table_;
};

struct FeatureLayout {
  uint64_t serial = new_serial();       ///< no other layout of this process has it (for caches)
  /// Per edge: 1 if no cluster may cross it; empty without feature edges (use is_feature_edge).
  std::vector<uint8_t> edge_feature;
  std::vector<int32_t> feature_edges;   ///< ids of the feature edges
  /// Per vertex: number of feature edges; empty without feature edges (then there are no curves,
  /// whose ends are what reads it).
  std::vector<int32_t> feature_degree;
  /// Per vertex: fans once feature edges are cut. Empty, as are vertex_feature and
  /// vertex_corner, on a mesh without feature edges whose vertices are all manifold (one sector
  /// each, none on a feature, no corner: 4.5 bytes a triangle of a large closed scan not kept);
  /// read them with sectors_of, is_feature_vertex and is_corner. Empty too (but not those two)
  /// where the only feature edges are boundary edges at manifold vertices (one sector each).
  std::vector<int32_t> sectors;
  /// The sector of each face around the vertices of more than one sector (their faces in
  /// Mesh::for_each_face order): sector_slot_vertex lists those vertices in increasing order,
  /// and the k-th one's faces start at sector_slot_offsets[k] in sector_of_slot. Use sector_of().
  std::vector<int32_t> sector_slot_vertex, sector_slot_offsets, sector_of_slot;
  std::vector<uint8_t> vertex_feature;  ///< per vertex: on a feature curve, or a corner (or empty)
  bool has_feature_vertices = false;    ///< any vertex_feature set (else no edge ids are needed)
  std::vector<uint8_t> vertex_corner;   ///< per vertex: always kept (or empty)
  int32_t num_vertices = 0, num_edges = 0;  ///< of the mesh the layout was built on
  /// Curves: open segments run from corner to corner (both included); closed loops hold only
  /// curve vertices (start not repeated).
  std::vector<int32_t> curve_offsets{0};
  std::vector<int32_t> curve_vertices;
  std::vector<uint8_t> curve_closed;
  /// Curve of each non-corner feature vertex, else -1; empty when there are no curves (use curve_of).
  std::vector<int32_t> vertex_curve;
  /// Boundary vertices where the boundary turns sharply, sharpest first (curve_bends.hpp): the draw
  /// keeps them, up to an eighth of its count.
  std::vector<int32_t> curve_bends;
  /// Corners of triangles that are pieces of their own (Mesh::loose_face), sorted: each piece keeps
  /// its triangle, so the draw forces them and the collapses lock them. Empty unless the mesh has
  /// many pieces (Mesh::many_pieces).
  std::vector<int32_t> loose_vertices;
  /// Corners of the two triangles across one inconsistently oriented edge per component, sorted:
  /// the decimation works in one winding per component (Mesh::winding_flips) and gives each
  /// output triangle its source face's winding back, so these two triangles stay (the draw
  /// forces their corners, the collapses lock them) and the output stays inconsistently oriented
  /// where the input was. Empty when no edge is.
  std::vector<int32_t> winding_seam_vertices;
  /// Mesh boundary loops (cycles of edges with one triangle, continued at a vertex within one
  /// fan: loops touching at a pinch stay apart), as vertex sets: each must meet three clusters
  /// or it closes up in the output, whatever corners split it into curves.
  std::vector<int32_t> boundary_loop_offsets{0};
  std::vector<int32_t> boundary_loop_vertices;
  /// Only when the mesh has pinched vertices (else empty): which vertices are pinched (several
  /// fans, every edge at them one- or two-sided and consistently oriented) and the sheet of
  /// every face (faces joined across two-face edges), so that the partition check can ask each
  /// fan of a pinched sample to stay on its own sheet.
  std::vector<uint8_t> vertex_pinched;
  std::vector<int32_t> face_sheet;
  /// 6 * (sectors - (sum of incident edge copies) / 2 + incident faces / 3): summed over a
  /// cluster's vertices it gives six times the cluster's Euler characteristic up to the terms
  /// of edges and faces shared with other clusters (see partition.cpp). Empty without feature
  /// edges, or where all are boundary edges at manifold vertices: there every edge is one copy
  /// and every vertex one sector, and chi_of computes it.
  std::vector<int32_t> chi_constant;
  DerivedTable sampling_table;  ///< sampling.cpp's importance table for its last parameters
  DerivedTable selection_uniforms;  ///< sampling.cpp's per-vertex uniforms of the seed drawn last
  DerivedTable candidate_order;     ///< candidate_order.cpp's vertices in the order a slider's draws take them
  DerivedTable quadric_frame;   ///< refine.cpp's normalisation frame (it depends on the mesh only)
  DerivedTable sliver_heavy;    ///< refine.cpp's sliver_heavy verdict (it depends on the mesh only)
  int32_t region_border_edges = 0;
  int32_t flagged_edges = 0;
  int32_t crease_edges = 0;

  int32_t num_curves() const { return static_cast<int32_t>(curve_closed.size()); }
  bool is_feature_edge(int32_t e) const { return !edge_feature.empty() && edge_feature[e]; }
  bool is_feature_vertex(int32_t v) const { return !vertex_feature.empty() && vertex_feature[v]; }
  bool is_corner(int32_t v) const { return !vertex_corner.empty() && vertex_corner[v]; }
  /// sectors[v], or where that table is empty 1 for a vertex in faces and 0 for an isolated one.
  int32_t sectors_of(const Mesh& mesh, int32_t v) const;
  /// The curve of vertex v, -1 for none.
  int32_t curve_of(int32_t v) const { return vertex_curve.empty() ? -1 : vertex_curve[v]; }
  /// Copies of edge e in the mesh cut along the feature edges.
  int32_t edge_copies(const Mesh& mesh, int32_t e) const { return is_feature_edge(e) ? mesh.edge_face_count(e) : 1; }
  /// chi_constant of vertex v.
  int32_t chi_of(const Mesh& mesh, int32_t v) const;
  /// Sector of face f at vertex v (f must contain v).
  int32_t sector_of(const Mesh& mesh, int32_t v, int32_t f) const;
};

/// face_region: one id per caller triangle (indexed like the caller's triangle array), or null.
/// flagged_edges: pairs of caller vertex ids; each must be an edge of the mesh (else
/// std::invalid_argument). feature_angle (radians, 0 = off): edges whose two triangles meet at a
/// dihedral angle above it (creases) become features too, so sharp edges are sampled as curves.
std::shared_ptr<const FeatureLayout> build_feature_layout(const Mesh& mesh, const int32_t* face_region,
                                                          int64_t face_region_count, const int32_t* flagged_edges,
                                                          int64_t num_flagged_edges, double feature_angle = 0.0);

}  // namespace topstoc
