// The costs of one wide vertex's collapses, kept between its evaluations (Collapser::evaluate).
//
// A fan's centre is evaluated again after every collapse on its rim, and each evaluation costs
// every one of its neighbours (tens of thousands on a fanned cap) although one or two of them
// changed. A cost is a pure function of its two ends' quadrics, positions and weights, so a kept
// cost stands while neither end has changed since it was computed: the collapser stamps each
// change with a clock (Collapser::changed_at_) and a kept cost with the clock it was computed at.
// Open addressing with linear probing, keyed by the neighbour's id.
#pragma once

#include <cstdint>
#include <vector>

namespace topstoc {

class CostCache {
 public:
  struct Entry {
    int32_t vertex = -1;  ///< -1: an empty slot
    uint32_t time = 0;    ///< the clock when the cost was computed
    double cost = 0.0;
  };

  /// The entry kept for `vertex`, or nullptr.
  const Entry* find(int32_t vertex) const {
    if (slots_.empty()) return nullptr;
    for (size_t i = slot(vertex);; i = (i + 1) & mask()) {
      if (slots_[i].vertex == vertex) return &slots_[i];
      if (slots_[i].vertex < 0) return nullptr;
    }
  }

  /// Keeps `cost` for `vertex`, computed at `time`; `alive(v)` says which entries a regrowth
  /// keeps (those of removed vertices are dropped there).
  template <class Alive>
  void put(int32_t vertex, uint32_t time, double cost, const Alive& alive) {
    if (2 * (used_ + 1) > slots_.size()) regrow(alive);
    for (size_t i = slot(vertex);; i = (i + 1) & mask()) {
      if (slots_[i].vertex < 0) ++used_;
      if (slots_[i].vertex < 0 || slots_[i].vertex == vertex) {
        slots_[i] = {vertex, time, cost};
        return;
      }
    }
  }

  void clear() {
    slots_.clear();
    used_ = 0;
    shift_ = 64;
  }

 private:
  size_t mask() const { return slots_.size() - 1; }
  // Fibonacci hashing: the product's high bits, which every bit of the id moves.
  size_t slot(int32_t vertex) const { return size_t((uint64_t(uint32_t(vertex)) * 0x9E3779B97F4A7C15ull) >> shift_); }

  template <class Alive>
  void regrow(const Alive& alive) {
    std::vector<Entry> old;
    old.swap(slots_);
    size_t live = 0;
    for (const Entry& e : old) live += e.vertex >= 0 && alive(e.vertex);
    size_t size = 64;
    shift_ = 58;
    while (size < 3 * (live + 1)) size *= 2, --shift_;  // a third full at most: room to grow
    slots_.assign(size, Entry());
    used_ = 0;
    for (const Entry& e : old)
      if (e.vertex >= 0 && alive(e.vertex)) put(e.vertex, e.time, e.cost, alive);
  }

  std::vector<Entry> slots_;  // a power of two, at most half used
  size_t used_ = 0;
  int shift_ = 64;  // 64 - log2(slots_.size())
};

}  // namespace topstoc
