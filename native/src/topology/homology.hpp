// Z2 homology of cycles on a closed orientable surface: coordinates and linear algebra.
//
// A tree-cotree decomposition (Eppstein 2003) of a genus-g surface leaves 2g generator edges:
// a spanning tree T of the vertices, a spanning tree C of the faces across edges not in T, and
// the 2g edges in neither. Generator j's dual loop runs through C between the two faces of
// edge j and crosses a set of edges; a cycle's coordinate j is the parity of its edges in that
// set (its intersection number with the dual loop). The coordinates of the fundamental cycle
// of generator j are the unit vector j, so two cycles are homologous exactly when their
// coordinates agree, and a set of cycles spans H1 exactly when their coordinates do. Counted
// with signs on the consistently oriented surface, the same crossings give integer
// coordinates: homology over Z.
#pragma once

#include <cstdint>
#include <vector>

#include "topology/closed_surface.hpp"

namespace topstoc {

/// A vector over Z2, packed in 64-bit words.
struct Z2Vector {
  std::vector<uint64_t> words;

  Z2Vector() = default;
  explicit Z2Vector(int32_t size) : words((size + 63) / 64, 0) {}
  bool get(int32_t i) const { return (words[i >> 6] >> (i & 63)) & 1; }
  void flip(int32_t i) { words[i >> 6] ^= uint64_t(1) << (i & 63); }
  void add(const Z2Vector& o) {
    for (size_t k = 0; k < words.size(); ++k) words[k] ^= o.words[k];
  }
  bool zero() const {
    for (uint64_t w : words)
      if (w) return false;
    return true;
  }
  /// Highest set bit, or -1.
  int32_t top() const;
  bool operator==(const Z2Vector& o) const { return words == o.words; }
};

/// Incrementally built basis of a subspace of Z2^n (Gaussian elimination on the highest bit).
class Z2Basis {
 public:
  explicit Z2Basis(int32_t size) : pivot_(size, -1), size_(size) {}
  int32_t rank() const { return int32_t(rows_.size()); }
  /// `x` reduced by the basis: zero exactly when x lies in the span.
  Z2Vector reduce(Z2Vector x) const;
  /// Same, also recording which basis rows were added (bit k = row k).
  Z2Vector reduce(Z2Vector x, Z2Vector& used) const;
  bool contains(const Z2Vector& x) const { return reduce(x).zero(); }
  /// Adds x when independent; returns whether it was.
  bool insert(const Z2Vector& x);
  /// Row k as inserted after reduction (its top bit is its pivot).
  const Z2Vector& row(int32_t k) const { return rows_[k]; }
  /// Rows inserted as given, before reduction: row_source(k) = the k-th inserted vector.
  const Z2Vector& source(int32_t k) const { return sources_[k]; }

 private:
  std::vector<Z2Vector> rows_, sources_;
  std::vector<Z2Vector> combos_;   // row k = sum of sources marked in combos_[k]
  std::vector<int32_t> pivot_;  // bit -> row with that top bit
  int32_t size_;
};

class SurfaceHomology {
 public:
  /// Builds the decomposition of a closed orientable surface (BFS tree from vertex 0).
  explicit SurfaceHomology(const ClosedSurface& surface);

  /// 2g.
  int32_t dimension() const { return int32_t(generators_.size()); }
  /// The 2g edges in neither tree: their fundamental cycles form a basis of H1.
  const std::vector<int32_t>& generator_edges() const { return generators_; }
  /// Adds edge e's coordinates to x (x has dimension() bits).
  void add_edge(Z2Vector& x, int32_t e) const { add_edge(x.words.data(), e); }
  /// Same on raw words (dimension() bits).
  void add_edge(uint64_t* words, int32_t e) const {
    for (int32_t i = crossing_offsets_[e]; i < crossing_offsets_[e + 1]; ++i)
      words[crossing_[i] >> 6] ^= uint64_t(1) << (crossing_[i] & 63);
  }
  /// Adds the integer coordinates of edge e traversed forward (lower to higher vertex) or
  /// backward to x: signed intersection numbers with the dual loops on the oriented surface.
  void add_edge_signed(std::vector<int64_t>& x, int32_t e, bool forward) const {
    for (int32_t i = crossing_offsets_[e]; i < crossing_offsets_[e + 1]; ++i)
      x[crossing_[i]] += forward ? crossing_sign_[i] : -crossing_sign_[i];
  }
  /// Calls f(j, sign) for each dual loop j crossing edge e (sign +1 when it crosses from the
  /// edge's left face).
  template <class F>
  void for_each_crossing(int32_t e, F f) const {
    for (int32_t i = crossing_offsets_[e]; i < crossing_offsets_[e + 1]; ++i) f(crossing_[i], int(crossing_sign_[i]));
  }
  /// Integer coordinates of a closed vertex loop: equal exactly when two loops are homologous
  /// over Z (with their orientations).
  std::vector<int64_t> integer_class_of_loop(const ClosedSurface& surface, const std::vector<int32_t>& loop) const;
  /// Coordinates of a cycle given as edges (each once), or as a closed vertex sequence.
  Z2Vector class_of_edges(const std::vector<int32_t>& edges) const;
  Z2Vector class_of_loop(const ClosedSurface& surface, const std::vector<int32_t>& loop) const;
  /// True when `edges` is a cycle (every vertex of even degree).
  static bool is_cycle(const ClosedSurface& surface, const std::vector<int32_t>& edges);

 private:
  std::vector<int32_t> generators_;
  std::vector<int32_t> crossing_offsets_, crossing_;  // per edge: the dual loops crossing it
  std::vector<int8_t> crossing_sign_;                 // and in which direction
};

}  // namespace topstoc
