// The link of one vertex of a triangle mesh, as arcs: for each triangle (s, a, b) around
// vertex s, the arc a -> b. Shared by the partition check (a sample's link in the decimated mesh
// before it is emitted) and the final output check (an output vertex's link). Valences are
// mostly small, so lookups are linear scans up to kScan neighbours and a hash map above (a fan's
// centre has thousands).
#pragma once

#include <algorithm>
#include <cstdint>
#include <utility>
#include <unordered_map>
#include <vector>

namespace topstoc {

struct LinkArcs {
  struct Neighbour {
    int32_t id;
    int32_t out = 0, in = 0;  // arcs leaving / entering this neighbour
    int32_t next = -1;        // index of the neighbour the arc leaving it goes to
  };
  /// The neighbours of the current link. Its storage outlives clear(), and the ids sit in an
  /// array of their own, so a lookup scans a few packed integers and adding one allocates
  /// nothing (this list is rebuilt for every sample and every output vertex).
  class Neighbours {
   public:
    const Neighbour* begin() const { return items_.data(); }
    const Neighbour* end() const { return items_.data() + size_; }
    size_t size() const { return size_t(size_); }
    Neighbour& operator[](size_t i) { return items_[i]; }
    const Neighbour& operator[](size_t i) const { return items_[i]; }
    void clear() { size_ = 0; }  // the map is made again when a link outgrows the scan
    int32_t index(int32_t id) {
      if (size_ <= kScan) {
        const int32_t* ids = ids_.data();
        for (int32_t i = 0; i < size_; ++i)
          if (ids[i] == id) return i;
      } else if (const auto found = map_.find(id); found != map_.end()) {
        return found->second;
      }
      if (size_ == int32_t(ids_.size())) {
        ids_.resize(2 * ids_.size() + 16);
        items_.resize(ids_.size());
      }
      ids_[size_] = id;
      items_[size_] = {id};
      if (size_ == kScan) {  // the link outgrows the scan: every id so far into the map
        map_.clear();
        for (int32_t i = 0; i <= size_; ++i) map_.emplace(ids_[i], i);
      } else if (size_ > kScan) {
        map_.emplace(id, size_);
      }
      return size_++;
    }

   private:
    static constexpr int32_t kScan = 64;
    std::vector<int32_t> ids_;
    std::vector<Neighbour> items_;
    std::unordered_map<int32_t, int32_t> map_;  // id -> index, while size_ > kScan
    int32_t size_ = 0;
  };
  Neighbours neighbours;
  int32_t arcs = 0;
  bool reversed = false;  // some arc a -> b has its reverse b -> a too

  void clear() {
    neighbours.clear();
    arcs = 0;
    reversed = false;
  }
  int32_t index(int32_t id) { return neighbours.index(id); }
  void add(int32_t from, int32_t to) {
    const int32_t a = index(from), b = index(to);
    if (neighbours[b].next == a) reversed = true;
    ++neighbours[a].out, ++neighbours[b].in;
    neighbours[a].next = b;
    ++arcs;
  }
  /// A triangle appears twice: once more in the same orientation, or in both.
  bool repeated() const {
    if (reversed) return true;
    for (const auto& n : neighbours)
      if (n.out > 1 || n.in > 1) return true;
    return false;
  }
  /// Fans: paths and cycles of arcs. (Call only when !repeated().)
  int32_t fans() const {
    int32_t count = 0, covered = 0;
    for (size_t i = 0; i < neighbours.size(); ++i) {
      if (neighbours[i].in != 0) continue;
      ++count;  // a path starts here
      for (int32_t v = int32_t(i); neighbours[v].next >= 0; v = neighbours[v].next) ++covered;
    }
    // The arcs not on a path lie on cycles; walk each once.
    std::vector<uint8_t> seen(neighbours.size(), 0);
    for (size_t i = 0; i < neighbours.size() && covered < arcs; ++i) {
      if (seen[i] || neighbours[i].in == 0 || neighbours[i].next < 0) continue;
      bool on_path = false;
      int32_t v = int32_t(i), steps = 0;
      while (!seen[v] && neighbours[v].next >= 0 && steps <= arcs) seen[v] = 1, v = neighbours[v].next, ++steps;
      if (v != int32_t(i)) on_path = true;  // reached a path's end or another walk
      if (!on_path) ++count, covered += steps;
    }
    return count;
  }
  /// The arcs form one path or one cycle: the triangles around the sample are one consistently
  /// oriented fan. (Call only when !repeated(): every neighbour then has out, in <= 1.)
  bool single_fan() const {
    int32_t start = 0, starts = 0;
    for (size_t i = 0; i < neighbours.size(); ++i)
      if (neighbours[i].in == 0) start = int32_t(i), ++starts;
    if (starts > 1) return false;
    int32_t walked = 0;
    for (int32_t v = start; walked <= arcs;) {
      const int32_t w = neighbours[v].next;
      if (w < 0) break;  // end of a path
      ++walked;
      if (w == start) break;  // closed the cycle
      v = w;
    }
    return walked == arcs;
  }
};

/// True when `count` >= 3 arcs (fields `from`, `to`) form one cycle: following each arc to the
/// arc leaving its head (the first such) comes back to the start after exactly `count` arcs.
/// Then the arcs' tails are `count` distinct vertices, each with one arc in and one out: the
/// link of a vertex inside a surface, one consistently oriented fan (what LinkArcs finds with
/// !repeated(), single_fan() and every neighbour's in + out == 2). The common case, checked
/// without building the LinkArcs; false for anything else. Up to kScanArcs arcs the next arc is
/// found by a scan; past them (a fan's centre, a cone's apex: a scan per step would cost the
/// count squared when the arcs run backwards) in the arcs sorted by tail, the same first one.
constexpr int32_t kScanArcs = 64;

// one_cycle's walk: next(at) is the first arc after arcs[0] leaving `at`, or -1.
template <class Arc, class Next>
bool walks_one_cycle(const Arc* arcs, int32_t count, Next&& next) {
  const int32_t start = arcs[0].from;
  int32_t at = arcs[0].to, steps = 1;
  while (at != start) {
    if (++steps > count) return false;  // a cycle that misses the start
    const int32_t j = next(at);
    if (j < 0) return false;  // a path's end
    at = arcs[j].to;
  }
  return steps == count;
}

template <class Arc>
bool one_cycle(const Arc* arcs, int32_t count) {
  if (count < 3) return false;  // two arcs a -> b, b -> a are one triangle twice
  if (count <= kScanArcs)
    return walks_one_cycle(arcs, count, [&](int32_t at) {
      for (int32_t j = 1; j < count; ++j)
        if (arcs[j].from == at) return j;
      return int32_t(-1);
    });
  std::vector<std::pair<int32_t, int32_t>> by_tail;  // (from, index) of arcs 1..count-1, sorted
  by_tail.reserve(size_t(count - 1));
  for (int32_t j = 1; j < count; ++j) by_tail.push_back({arcs[j].from, j});
  std::sort(by_tail.begin(), by_tail.end());
  return walks_one_cycle(arcs, count, [&](int32_t at) {
    const auto found = std::lower_bound(by_tail.begin(), by_tail.end(), std::pair<int32_t, int32_t>{at, 0});
    return found != by_tail.end() && found->first == at ? found->second : int32_t(-1);
  });
}

}  // namespace topstoc
