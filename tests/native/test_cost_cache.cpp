// CostCache (a wide vertex's kept collapse costs): what is put is found, the last put wins, and a
// regrowth keeps exactly the entries of live vertices; checked against a std::map.
#include <doctest/doctest.h>

#include <cstdint>
#include <map>
#include <random>
#include <utility>
#include <vector>

#include "decimate/cost_cache.hpp"

using topstoc::CostCache;

TEST_CASE("kept costs are found as put, through regrowths that drop removed vertices") {
  std::mt19937 random(7);
  std::vector<uint8_t> alive(50000, 1);
  auto is_alive = [&](int32_t v) { return alive[v] != 0; };
  CostCache cache;
  std::map<int32_t, std::pair<uint32_t, double>> reference;
  CHECK(cache.find(3) == nullptr);
  for (uint32_t step = 0; step < 200000; ++step) {
    const int32_t v = int32_t(random() % alive.size());
    if (random() % 8 == 0) {
      alive[v] = 0;  // removed: a regrowth may drop it; until then it may still be found
      continue;
    }
    if (!alive[v]) continue;
    const double cost = double(random() % 1000) / 7.0;
    cache.put(v, step, cost, is_alive);
    reference[v] = {step, cost};
  }
  int64_t found = 0;
  for (const auto& [v, kept] : reference) {
    const CostCache::Entry* e = cache.find(v);
    if (!alive[v]) continue;  // dropped or not: never read for a removed vertex
    REQUIRE(e != nullptr);
    CHECK(e->vertex == v);
    CHECK(e->time == kept.first);
    CHECK(e->cost == kept.second);
    ++found;
  }
  CHECK(found > 10000);
  for (int32_t v = 0; v < int32_t(alive.size()); ++v)
    if (!reference.count(v)) CHECK(cache.find(v) == nullptr);
  cache.clear();
  CHECK(cache.find(reference.begin()->first) == nullptr);
}
