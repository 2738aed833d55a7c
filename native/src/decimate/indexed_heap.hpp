// A binary min-heap over the ids 0..n-1 that holds each id at most once and can change an id's
// key in place. Greedy collapses re-key a handful of vertices per step; re-keying in place
// keeps the heap at n entries instead of filling it with superseded copies (on a million
// entries those copies, not the collapses, dominated the time).
#pragma once

#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

namespace topstoc {

class IndexedHeap {
 public:
  explicit IndexedHeap(int32_t n) : position_(n, -1) {}

  bool empty() const { return heap_.empty(); }
  bool contains(int32_t id) const { return position_[id] >= 0; }
  int32_t top() const { return heap_.front().id; }
  double top_key() const { return heap_.front().key; }
  double key_of(int32_t id) const { return heap_[position_[id]].key; }  ///< id must be present

  /// Inserts `id` with `key`, or moves it to `key` if present.
  void set(int32_t id, double key) {
    if (position_[id] < 0) {
      position_[id] = static_cast<int32_t>(heap_.size());
      heap_.push_back({key, id});
    } else {
      heap_[position_[id]].key = key;
    }
    sift_down(sift_up(position_[id]));
  }

  /// Replaces the contents with these ids and keys (each id at most once), in linear time.
  void assign(const std::vector<int32_t>& ids, const std::vector<double>& keys) {
    for (const Entry& e : heap_) position_[e.id] = -1;
    heap_.clear();
    for (std::size_t i = 0; i < ids.size(); ++i) {
      position_[ids[i]] = static_cast<int32_t>(heap_.size());
      heap_.push_back({keys[i], ids[i]});
    }
    for (int32_t at = static_cast<int32_t>(heap_.size()) / 2 - 1; at >= 0; --at) sift_down(at);
  }

  void remove(int32_t id) {
    const int32_t at = position_[id];
    if (at < 0) return;
    const Entry last = heap_.back();
    heap_.pop_back();
    position_[id] = -1;
    if (last.id == id) return;
    place(at, last);
    sift_down(sift_up(at));
  }

 private:
  struct Entry {
    double key;
    int32_t id;
    // Ties by id, so the order never depends on the platform.
    bool operator<(const Entry& o) const { return key < o.key || (key == o.key && id < o.id); }
  };

  void place(int32_t at, const Entry& e) {
    heap_[at] = e;
    position_[e.id] = at;
  }

  int32_t sift_up(int32_t at) {
    const Entry e = heap_[at];
    while (at > 0) {
      const int32_t parent = (at - 1) / 2;
      if (!(e < heap_[parent])) break;
      place(at, heap_[parent]);
      at = parent;
    }
    place(at, e);
    return at;
  }

  void sift_down(int32_t at) {
    const Entry e = heap_[at];
    const int32_t size = static_cast<int32_t>(heap_.size());
    for (;;) {
      int32_t child = 2 * at + 1;
      if (child >= size) break;
      if (child + 1 < size && heap_[child + 1] < heap_[child]) ++child;
      if (!(heap_[child] < e)) break;
      place(at, heap_[child]);
      at = child;
    }
    place(at, e);
  }

  std::vector<Entry> heap_;
  std::vector<int32_t> position_;
};

}  // namespace topstoc
