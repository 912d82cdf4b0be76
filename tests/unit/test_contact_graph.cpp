// Tests for the contact-graph levels (strongly connected components in topological order, notes
// 1.6) and the islands of finite-mass bodies.
#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <stdexcept>

#include "solvers/contact/contact_graph.h"

namespace {

using monolith::solvers::contact::computeIslands;
using monolith::solvers::contact::computeLevels;
using monolith::solvers::contact::ContactLevels;
using monolith::solvers::contact::Islands;
using Edges = std::vector<std::pair<int, int>>;
using Lists = std::vector<std::vector<int>>;

TEST(ContactLevels, ChainFromTheBottomUp) {
  // 3 below 1 below 0 below 2.
  const ContactLevels levels = computeLevels(4, {{1, 0}, {3, 1}, {0, 2}});
  EXPECT_EQ(levels.count(), 4);
  EXPECT_EQ(levels.levelOf, (std::vector<int>{2, 1, 3, 0}));
  EXPECT_EQ(levels.nodes, (Lists{{3}, {1}, {0}, {2}}));
}

TEST(ContactLevels, CycleCollapsesIntoOneLevel) {
  // 0 below the cycle 1 -> 2 -> 3 -> 1 (bodies resting on each other), 4 above 3.
  const ContactLevels levels = computeLevels(5, {{0, 1}, {1, 2}, {2, 3}, {3, 1}, {3, 4}});
  EXPECT_EQ(levels.count(), 3);
  EXPECT_EQ(levels.levelOf, (std::vector<int>{0, 1, 1, 1, 2}));
  EXPECT_EQ(levels.nodes, (Lists{{0}, {1, 2, 3}, {4}}));
  // A mutual pair (each below the other) and a self edge.
  const ContactLevels mutual = computeLevels(2, {{0, 1}, {1, 0}, {1, 1}});
  EXPECT_EQ(mutual.nodes, (Lists{{0, 1}}));
}

TEST(ContactLevels, StaticGroundIsAtTheBottom) {
  // Ground is node 5; two stacks 0-2-4 and 1-3 on it; node 6 touches nothing.
  const ContactLevels levels = computeLevels(7, {{5, 0}, {5, 1}, {0, 2}, {1, 3}, {2, 4}});
  EXPECT_EQ(levels.levelOf[5], 0);
  EXPECT_EQ(levels.count(), 7);
  // Ties (several components ready) go to the smallest node: 0, 1, 2, 3, 4 after the ground,
  // and the isolated 6 last (it is ready from the start, but 5 < 6 and then 0 < 6, ...).
  EXPECT_EQ(levels.nodes, (Lists{{5}, {0}, {1}, {2}, {3}, {4}, {6}}));
}

TEST(ContactLevels, EmptyAndIsolated) {
  EXPECT_EQ(computeLevels(0, {}).count(), 0);
  const ContactLevels levels = computeLevels(3, {});
  EXPECT_EQ(levels.nodes, (Lists{{0}, {1}, {2}}));
  EXPECT_THROW(computeLevels(2, {{0, 2}}), std::invalid_argument);
}

// Reachability closure for the brute-force check of components and order.
std::vector<std::vector<char>> reachability(int n, const Edges& edges) {
  std::vector<std::vector<char>> reach(n, std::vector<char>(n, 0));
  for (int v = 0; v < n; ++v) reach[v][v] = 1;
  for (const auto& [a, b] : edges) reach[a][b] = 1;
  for (int k = 0; k < n; ++k)
    for (int i = 0; i < n; ++i)
      if (reach[i][k])
        for (int j = 0; j < n; ++j) reach[i][j] = reach[i][j] || reach[k][j];
  return reach;
}

TEST(ContactLevels, RandomGraphsIndependentOfEdgeOrder) {
  std::mt19937 rng(41);
  const int n = 60;
  for (int graph = 0; graph < 5; ++graph) {
    std::uniform_int_distribution<int> node(0, n - 1);
    Edges edges;
    for (int e = 0; e < 90; ++e) edges.emplace_back(node(rng), node(rng));
    edges.push_back(edges.front());  // a duplicate edge changes nothing either
    const ContactLevels levels = computeLevels(n, edges);

    // Same level <=> same strongly connected component; edges between components go upwards.
    const auto reach = reachability(n, edges);
    for (int a = 0; a < n; ++a) {
      for (int b = 0; b < n; ++b) {
        const bool sameComponent = reach[a][b] && reach[b][a];
        ASSERT_EQ(levels.levelOf[a] == levels.levelOf[b], sameComponent) << a << " " << b;
      }
    }
    for (const auto& [below, above] : edges)
      EXPECT_LE(levels.levelOf[below], levels.levelOf[above]);
    for (int l = 0; l < levels.count(); ++l) {
      EXPECT_TRUE(std::is_sorted(levels.nodes[l].begin(), levels.nodes[l].end()));
      for (int v : levels.nodes[l]) EXPECT_EQ(levels.levelOf[v], l);
    }

    for (int shuffle = 0; shuffle < 20; ++shuffle) {
      Edges shuffled = edges;
      std::shuffle(shuffled.begin(), shuffled.end(), rng);
      const ContactLevels again = computeLevels(n, shuffled);
      ASSERT_EQ(again.levelOf, levels.levelOf);
      ASSERT_EQ(again.nodes, levels.nodes);
    }
  }
}

TEST(ContactLevels, HundredThousandNodeChainAndCycle) {
  const int n = 100000;
  Edges chain;
  for (int v = n - 1; v > 0; --v) chain.emplace_back(v - 1, v);  // reversed input order
  const ContactLevels levels = computeLevels(n, chain);
  ASSERT_EQ(levels.count(), n);
  for (int v = 0; v < n; ++v) ASSERT_EQ(levels.levelOf[v], v);

  // Closing the chain into one cycle: a single level of all n bodies (Tarjan's deepest case).
  Edges cycle = chain;
  cycle.emplace_back(n - 1, 0);
  const ContactLevels one = computeLevels(n, cycle);
  ASSERT_EQ(one.count(), 1);
  EXPECT_EQ(static_cast<int>(one.nodes[0].size()), n);
}

TEST(ContactIslands, StaticNodeDoesNotMergeIslands) {
  // 0 and 5 are static; stacks {1, 2} and {3, 4} both rest on 0; 6 touches nothing.
  const std::vector<char> infinite = {1, 0, 0, 0, 0, 1, 0};
  const Edges pairs = {{0, 3}, {1, 2}, {0, 1}, {3, 4}, {2, 0}, {0, 5}, {4, 5}};
  const Islands islands = computeIslands(7, pairs, infinite);
  EXPECT_EQ(islands.islandOf, (std::vector<int>{-1, 0, 0, 1, 1, -1, 2}));
  EXPECT_EQ(islands.members, (Lists{{1, 2}, {3, 4}, {6}}));
  // (0, 5) joins two static bodies and belongs to no island.
  EXPECT_EQ(islands.pairs, (Lists{{1, 2, 4}, {0, 3, 6}, {}}));
}

TEST(ContactIslands, MergingThroughDynamicBodiesAndOrder) {
  // A chain 5 - 2 - 7 - 0 of dynamic bodies, given out of order, forms one island led by 0.
  const std::vector<char> infinite(8, 0);
  const Edges pairs = {{7, 0}, {5, 2}, {3, 4}, {2, 7}};
  const Islands islands = computeIslands(8, pairs, infinite);
  EXPECT_EQ(islands.members, (Lists{{0, 2, 5, 7}, {1}, {3, 4}, {6}}));
  EXPECT_EQ(islands.pairs, (Lists{{0, 1, 3}, {}, {2}, {}}));
  EXPECT_THROW(computeIslands(8, pairs, std::vector<char>(7, 0)), std::invalid_argument);
}

TEST(ContactGraphReuse, ResultsWrittenOverEarlierOnesEqualFreshOnes) {
  // The contact stages rebuild the graph into last step's results (their storage is kept);
  // nothing of the earlier graph may show through, whether the new one is larger or smaller.
  std::mt19937 rng(7);
  ContactLevels levels;
  Islands islands;
  for (int graph = 0; graph < 40; ++graph) {
    const int n = std::uniform_int_distribution<int>(1, 50)(rng);
    std::uniform_int_distribution<int> node(0, n - 1);
    Edges edges;
    const int m = std::uniform_int_distribution<int>(0, 2 * n)(rng);
    for (int e = 0; e < m; ++e) edges.emplace_back(node(rng), node(rng));
    std::vector<char> infinite(n);
    for (auto& f : infinite) f = std::uniform_int_distribution<int>(0, 5)(rng) == 0;
    computeLevels(n, edges, levels);
    const ContactLevels freshLevels = computeLevels(n, edges);
    ASSERT_EQ(levels.levelOf, freshLevels.levelOf) << graph;
    ASSERT_EQ(levels.nodes, freshLevels.nodes) << graph;
    computeIslands(n, edges, infinite, islands);
    const Islands freshIslands = computeIslands(n, edges, infinite);
    ASSERT_EQ(islands.islandOf, freshIslands.islandOf) << graph;
    ASSERT_EQ(islands.members, freshIslands.members) << graph;
    ASSERT_EQ(islands.pairs, freshIslands.pairs) << graph;
  }
}

}  // namespace
