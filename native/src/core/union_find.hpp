// Disjoint sets over 0..n-1 (union-find), with an optional parity per element.
//
// Plain union-find gives connected components in near-linear time (vertices joined by edges,
// faces joined across edges). The parity variant also records, for every element, one bit
// relative to its set's root: joining a and b with parity p asserts parity(a) xor parity(b) = p,
// and a join that contradicts the bits already recorded reports a conflict. Topology uses it to
// orient triangles while it groups them (p = 1 when two triangles must be flipped relative to
// each other); a conflict inside a group means the group is not orientable.
#pragma once

#include <cstdint>
#include <numeric>
#include <utility>
#include <vector>

namespace topstoc {

class UnionFind {
 public:
  explicit UnionFind(int32_t n = 0) { reset(n); }

  /// n singletons.
  void reset(int32_t n) {
    parent_.resize(n);
    std::iota(parent_.begin(), parent_.end(), 0);
  }

  int32_t size() const { return static_cast<int32_t>(parent_.size()); }

  /// Root of x's set (path halving).
  int32_t find(int32_t x) {
    while (parent_[x] != x) x = parent_[x] = parent_[parent_[x]];
    return x;
  }

  /// Joins the sets of a and b; returns false when they were already one set. The smaller root
  /// id becomes the root, so results do not depend on the order of equivalent joins.
  bool unite(int32_t a, int32_t b) {
    a = find(a);
    b = find(b);
    if (a == b) return false;
    if (a < b)
      parent_[b] = a;
    else
      parent_[a] = b;
    return true;
  }

 private:
  std::vector<int32_t> parent_;
};

/// Union-find that threads may share: a root is linked below a smaller root with a
/// compare-and-swap, so every root is the smallest element of its set whatever the interleaving,
/// and the sets come out the same for any number of threads. Path halving only ever points an
/// element at one of its ancestors, so a lost update does no harm. Read roots once every join is
/// done (find is then exact).
class SharedUnionFind {
 public:
  explicit SharedUnionFind(int32_t n = 0) : parent_(n) { std::iota(parent_.begin(), parent_.end(), 0); }

  int32_t find(int32_t x) {
    for (;;) {
      const int32_t p = __atomic_load_n(&parent_[x], __ATOMIC_RELAXED);
      if (p == x) return x;
      const int32_t grand = __atomic_load_n(&parent_[p], __ATOMIC_RELAXED);
      if (grand != p) __atomic_store_n(&parent_[x], grand, __ATOMIC_RELAXED);
      x = grand;
    }
  }

  void unite(int32_t a, int32_t b) {
    for (;;) {
      int32_t ra = find(a), rb = find(b);
      if (ra == rb) return;
      if (ra > rb) std::swap(ra, rb);
      int32_t expected = rb;
      if (__atomic_compare_exchange_n(&parent_[rb], &expected, ra, false, __ATOMIC_RELAXED, __ATOMIC_RELAXED)) return;
    }
  }

  /// The parents, for a caller that keeps its own array of roots afterwards.
  std::vector<int32_t>& parents() { return parent_; }

 private:
  std::vector<int32_t> parent_;
};

class ParityUnionFind {
 public:
  explicit ParityUnionFind(int32_t n = 0) : parent_(n), parity_(n, 0) { std::iota(parent_.begin(), parent_.end(), 0); }

  /// Root of x's set; parity receives x's bit relative to that root.
  int32_t find(int32_t x, uint8_t& parity) {
    uint8_t p = 0;
    int32_t r = x;
    while (parent_[r] != r) {
      p ^= parity_[r];
      r = parent_[r];
    }
    // Path compression: point every element on the path straight at the root.
    uint8_t q = p;
    while (parent_[x] != r) {
      const int32_t next = parent_[x];
      const uint8_t step = parity_[x];
      parent_[x] = r;
      parity_[x] = q;
      q ^= step;
      x = next;
    }
    parity = p;
    return r;
  }

  int32_t find(int32_t x) {
    uint8_t ignored;
    return find(x, ignored);
  }

  /// Whether x is the root of its set (a read, unlike find, which shortens paths).
  bool is_root(int32_t x) const { return parent_[x] == x; }

  enum class Join { merged, consistent, conflict };

  /// Asserts parity(a) xor parity(b) == p. Returns merged when two sets became one, consistent
  /// when they already were one set and agree, conflict when they were one set and disagree.
  Join unite(int32_t a, int32_t b, uint8_t p) {
    uint8_t pa, pb;
    const int32_t ra = find(a, pa), rb = find(b, pb);
    if (ra == rb) return ((pa ^ pb) == p) ? Join::consistent : Join::conflict;
    const int32_t keep = ra < rb ? ra : rb, gone = ra < rb ? rb : ra;
    parent_[gone] = keep;
    parity_[gone] = static_cast<uint8_t>(pa ^ pb ^ p);
    return Join::merged;
  }

 private:
  std::vector<int32_t> parent_;
  std::vector<uint8_t> parity_;
};

}  // namespace topstoc
