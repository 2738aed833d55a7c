// one_cycle (link_arcs.hpp), the partition check's shortcut for a closed fan, against the
// general LinkArcs on every arc set drawn: random arcs among a few vertices, and shuffled
// cycles, some with one arc changed; and LinkArcs itself on links past its linear scan.
#include <doctest/doctest.h>

#include <algorithm>
#include <numeric>
#include <random>
#include <vector>

#include "decimate/link_arcs.hpp"

using topstoc::LinkArcs;

namespace {

struct Arc {
  int32_t from, to;
};

// What one_cycle claims, from the general structure: no repeat, one fan, and it is closed
// (every neighbour has an arc in and one out), with at least three arcs.
bool closed_fan(const std::vector<Arc>& arcs) {
  LinkArcs link;
  for (const Arc& a : arcs) link.add(a.from, a.to);
  if (arcs.size() < 3 || link.repeated() || link.fans() != 1) return false;
  for (const auto& nb : link.neighbours)
    if (nb.in != 1 || nb.out != 1) return false;
  return true;
}

}  // namespace

TEST_CASE("one_cycle is true exactly for a closed fan of three or more arcs") {
  std::mt19937 random(7);
  int32_t cycles = 0, others = 0;
  for (int trial = 0; trial < 20000; ++trial) {
    std::vector<Arc> arcs;
    const int32_t count = 1 + int32_t(random() % 9);
    if (trial % 2 == 0) {  // a cycle through `count` distinct vertices, shuffled, maybe broken
      std::vector<int32_t> ring(count);
      std::iota(ring.begin(), ring.end(), 10);
      std::shuffle(ring.begin(), ring.end(), random);
      for (int32_t i = 0; i < count; ++i) arcs.push_back({ring[i], ring[(i + 1) % count]});
      if (random() % 3 == 0) arcs[random() % count].to = 10 + int32_t(random() % (count + 1));
      if (random() % 4 == 0) arcs.pop_back();
    } else {  // arcs among few vertices: repeats, reversals, paths, several cycles
      for (int32_t i = 0; i < count; ++i) {
        const int32_t a = int32_t(random() % 6), b = int32_t(random() % 6);
        if (a != b) arcs.push_back({a, b});
      }
    }
    std::shuffle(arcs.begin(), arcs.end(), random);
    const bool expected = closed_fan(arcs);
    CHECK(topstoc::one_cycle(arcs.data(), int32_t(arcs.size())) == expected);
    ++(expected ? cycles : others);
  }
  CHECK(cycles > 1000);
  CHECK(others > 1000);
}

TEST_CASE("LinkArcs past its linear scan: the same neighbours, counts and fans as a plain count") {
  // Links of up to 3,000 neighbours (a fan's centre), where lookups go through the hash map:
  // each neighbour numbered in order of first appearance, its arcs counted, the fans found.
  std::mt19937 random(3);
  LinkArcs link;  // reused, as the partition check does: a small link after a large one
  for (int32_t size : {3000, 65, 66, 64, 200, 5}) {
    std::vector<int32_t> ids(size);
    for (int32_t i = 0; i < size; ++i) ids[i] = int32_t(random() % 1000000) * 8 + i % 8;
    std::sort(ids.begin(), ids.end());
    ids.erase(std::unique(ids.begin(), ids.end()), ids.end());
    std::shuffle(ids.begin(), ids.end(), random);
    const int32_t n = int32_t(ids.size());
    std::vector<Arc> arcs;
    for (int32_t i = 0; i < n; ++i) arcs.push_back({ids[i], ids[(i + 1) % n]});
    std::shuffle(arcs.begin(), arcs.end(), random);
    for (int variant = 0; variant < 3; ++variant) {
      std::vector<Arc> drawn = arcs;
      if (variant == 1) drawn.pop_back();               // a path: one fan, open
      if (variant == 2) drawn.push_back(drawn.front());  // a triangle twice
      link.clear();
      std::vector<int32_t> order;  // first appearance, as index() numbers them
      for (const Arc& a : drawn) {
        link.add(a.from, a.to);
        for (int32_t id : {a.from, a.to})
          if (std::find(order.begin(), order.end(), id) == order.end()) order.push_back(id);
      }
      REQUIRE(link.neighbours.size() == order.size());
      int32_t misplaced = 0;
      for (size_t i = 0; i < order.size(); ++i) misplaced += link.neighbours[i].id != order[i];
      CHECK(misplaced == 0);
      CHECK(link.repeated() == (variant == 2));
      if (variant < 2) {
        CHECK(link.fans() == 1);
        CHECK(link.single_fan());
      }
    }
  }
}

namespace {

// one_cycle as it was written before the sorted lookup: a scan for the next arc at every step.
bool one_cycle_by_scan(const std::vector<Arc>& arcs) {
  const int32_t count = int32_t(arcs.size());
  if (count < 3) return false;
  const int32_t start = arcs[0].from;
  int32_t at = arcs[0].to, steps = 1;
  while (at != start) {
    if (++steps > count) return false;
    int32_t next = -1;
    for (int32_t j = 1; j < count && next < 0; ++j)
      if (arcs[j].from == at) next = j;
    if (next < 0) return false;
    at = arcs[next].to;
  }
  return steps == count;
}

}  // namespace

TEST_CASE("one_cycle past its scan (a fan's centre): the same answer as the scan and as LinkArcs") {
  // Cycles of 60 to 2,000 arcs in order, backwards (the order a cone's lower apex lists them,
  // where the scan cost the count squared) and shuffled; then broken: an arc turned aside, one
  // left out, one repeated, one reversed, two cycles side by side.
  std::mt19937 random(11);
  int32_t cycles = 0, others = 0;
  for (int32_t size : {60, 64, 65, 66, 100, 777, 2000}) {
    std::vector<int32_t> ring(size);
    for (int32_t i = 0; i < size; ++i) ring[i] = 5 * i + int32_t(random() % 5);
    for (int variant = 0; variant < 7; ++variant)
      for (int order = 0; order < 3; ++order) {
        std::vector<Arc> arcs;
        for (int32_t i = 0; i < size; ++i) arcs.push_back({ring[i], ring[(i + 1) % size]});
        if (variant == 1) arcs[random() % size].to = ring[random() % size];
        if (variant == 2) arcs.erase(arcs.begin() + random() % size);
        if (variant == 3) arcs.push_back(arcs[random() % size]);
        if (variant == 4) std::swap(arcs[0].from, arcs[0].to);
        if (variant == 5)  // two cycles: the ring split in two halves
          arcs[size / 2 - 1].to = ring[0], arcs[size - 1].to = ring[size / 2];
        if (variant == 6) arcs.push_back({ring[0], ring[size / 2]});
        if (order == 1) std::reverse(arcs.begin(), arcs.end());
        if (order == 2) std::shuffle(arcs.begin(), arcs.end(), random);
        const bool got = topstoc::one_cycle(arcs.data(), int32_t(arcs.size()));
        CHECK(got == one_cycle_by_scan(arcs));
        CHECK(got == closed_fan(arcs));
        ++(got ? cycles : others);
      }
  }
  CHECK(cycles == 7 * 3);  // every unbroken cycle, whatever its order
  CHECK(others >= 6 * 7 * 3 - 6);  // an arc turned aside may land on its own head
}
