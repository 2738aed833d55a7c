// Union-find against a brute-force labelling of the same joins; the parity variant against a
// brute-force two-colouring.
#include <doctest/doctest.h>

#include <algorithm>
#include <random>
#include <tuple>
#include <utility>
#include <vector>

#include "core/union_find.hpp"

using topstoc::ParityUnionFind;
using topstoc::UnionFind;

namespace {

// Component of every element after the joins: the smallest element reachable (plain search).
std::vector<int32_t> brute_components(int32_t n, const std::vector<std::pair<int32_t, int32_t>>& joins) {
  std::vector<int32_t> label(n);
  for (int32_t v = 0; v < n; ++v) label[v] = v;
  for (bool changed = true; changed;) {
    changed = false;
    for (const auto& [a, b] : joins) {
      const int32_t low = std::min(label[a], label[b]);
      if (label[a] != low || label[b] != low) label[a] = label[b] = low, changed = true;
    }
  }
  return label;
}

}  // namespace

TEST_CASE("union-find: the root is the smallest id of each set, as a brute-force labelling says") {
  std::mt19937 random(7);
  for (int round = 0; round < 20; ++round) {
    const int32_t n = 1 + int32_t(random() % 200);
    UnionFind sets(n);
    std::vector<std::pair<int32_t, int32_t>> joins;
    std::vector<int32_t> label(n);
    for (int i = 0; i < n; ++i) {
      const int32_t a = int32_t(random() % n), b = int32_t(random() % n);
      const bool was_apart = sets.find(a) != sets.find(b);
      CHECK(sets.unite(a, b) == was_apart);
      joins.emplace_back(a, b);
    }
    const auto expected = brute_components(n, joins);
    for (int32_t v = 0; v < n; ++v) CHECK(sets.find(v) == expected[v]);
  }
}

TEST_CASE("parity union-find: conflicts exactly where no two-colouring satisfies the joins") {
  std::mt19937 random(11);
  for (int round = 0; round < 200; ++round) {
    const int32_t n = 2 + int32_t(random() % 7);
    ParityUnionFind sets(n);
    std::vector<std::tuple<int32_t, int32_t, uint8_t>> accepted;
    for (int i = 0; i < 2 * n; ++i) {
      const int32_t a = int32_t(random() % n), b = int32_t(random() % n);
      const uint8_t p = uint8_t(random() % 2);
      // Brute force: is there a colouring of all n elements meeting the accepted joins and this one?
      bool satisfiable = false;
      for (uint32_t colours = 0; colours < (1u << n) && !satisfiable; ++colours) {
        auto bit = [&](int32_t v) { return uint8_t((colours >> v) & 1u); };
        bool ok = (bit(a) ^ bit(b)) == p;
        for (const auto& [x, y, q] : accepted) ok = ok && (bit(x) ^ bit(y)) == q;
        satisfiable = ok;
      }
      const bool same_set = sets.find(a) == sets.find(b);
      const auto join = sets.unite(a, b, p);
      if (!satisfiable) {
        CHECK(join == ParityUnionFind::Join::conflict);
        continue;  // a conflicting join records nothing
      }
      CHECK(join == (same_set ? ParityUnionFind::Join::consistent : ParityUnionFind::Join::merged));
      accepted.emplace_back(a, b, p);
    }
    // The recorded bits themselves satisfy every accepted join.
    for (const auto& [x, y, q] : accepted) {
      uint8_t px, py;
      REQUIRE(sets.find(x, px) == sets.find(y, py));
      CHECK((px ^ py) == q);
    }
  }
}
