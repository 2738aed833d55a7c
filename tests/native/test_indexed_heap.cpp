// The indexed heap against std::priority_queue (insert, then pop all) and against a sorted set
// under random set / re-key / remove operations.
#include <doctest/doctest.h>

#include <functional>
#include <queue>
#include <random>
#include <set>
#include <vector>

#include "decimate/indexed_heap.hpp"

using topstoc::IndexedHeap;

TEST_CASE("indexed heap pops in the order of std::priority_queue, ties by id") {
  std::mt19937 random(3);
  const int32_t n = 500;
  IndexedHeap heap(n);
  std::priority_queue<std::pair<double, int32_t>, std::vector<std::pair<double, int32_t>>, std::greater<>> queue;
  for (int32_t id = 0; id < n; ++id) {
    const double key = double(random() % 50);  // many equal keys: the tie rule matters
    heap.set(id, key);
    queue.emplace(key, id);
  }
  while (!queue.empty()) {
    REQUIRE_FALSE(heap.empty());
    CHECK(heap.top_key() == queue.top().first);
    CHECK(heap.top() == queue.top().second);
    heap.remove(heap.top());
    queue.pop();
  }
  CHECK(heap.empty());
}

TEST_CASE("indexed heap under random set, re-key and remove agrees with a sorted set") {
  std::mt19937 random(5);
  const int32_t n = 300;
  IndexedHeap heap(n);
  std::set<std::pair<double, int32_t>> sorted;
  std::vector<double> key(n, -1);
  for (int step = 0; step < 20000; ++step) {
    const int32_t id = int32_t(random() % n);
    switch (random() % 4) {
      case 0:
      case 1: {  // insert or re-key
        const double k = double(random() % 1000) / 7.0;
        if (key[id] >= 0) sorted.erase({key[id], id});
        key[id] = k;
        sorted.insert({k, id});
        heap.set(id, k);
        break;
      }
      case 2:  // remove (also of an absent id: a no-op)
        if (key[id] >= 0) sorted.erase({key[id], id}), key[id] = -1;
        heap.remove(id);
        break;
      default:  // pop
        if (!sorted.empty()) {
          const auto [k, top] = *sorted.begin();
          REQUIRE(heap.top() == top);
          CHECK(heap.top_key() == k);
          sorted.erase(sorted.begin());
          key[top] = -1;
          heap.remove(top);
        }
    }
    REQUIRE(heap.empty() == sorted.empty());
    CHECK(heap.contains(id) == (key[id] >= 0));
    if (key[id] >= 0) CHECK(heap.key_of(id) == key[id]);
    if (!sorted.empty()) CHECK(heap.top() == sorted.begin()->second);
  }
}

TEST_CASE("indexed heap built at once pops like one built by inserts") {
  std::mt19937 random(7);
  const int32_t n = 400;
  IndexedHeap built(n), inserted(n);
  built.set(3, 1.0);  // assign replaces what was there
  std::vector<int32_t> ids;
  std::vector<double> keys;
  for (int32_t id = 0; id < n; ++id)
    if (random() % 3 != 0) {
      ids.push_back(id);
      keys.push_back(double(random() % 40));  // many ties
      inserted.set(id, keys.back());
    }
  built.assign(ids, keys);
  CHECK(built.contains(3) == inserted.contains(3));
  while (!inserted.empty()) {
    REQUIRE_FALSE(built.empty());
    CHECK(built.top() == inserted.top());
    CHECK(built.top_key() == inserted.top_key());
    built.remove(built.top());
    inserted.remove(inserted.top());
  }
  CHECK(built.empty());
}
