#pragma once
// The contact graph of Guendelman, Bridson & Fedkiw 2003 as the thesis's code builds it
// (notes 1.6): an edge "a below b" for bodies in contact, strongly connected components (cycles)
// collapsed, each component its own level in topological order, level 0 at the bottom (bodies
// nothing is below, e.g. the static ground). Also the islands: connected groups of finite-mass
// bodies (bodies of infinite mass do not connect islands), for parallel processing.
#include <utility>
#include <vector>

namespace monolith::solvers::contact {

struct ContactLevels {
  std::vector<int> levelOf;             // per node
  std::vector<std::vector<int>> nodes;  // per level, ascending node index
  int count() const { return static_cast<int>(nodes.size()); }
};

// Edges (below, above). Deterministic: the result depends only on nodeCount and the edge set
// (the order of `edges` does not matter). Isolated nodes get levels too.
ContactLevels computeLevels(int nodeCount, const std::vector<std::pair<int, int>>& belowAbove);
// The same into `out`, reusing its storage: the contact stages rebuild the graph every step,
// and once warm this allocates nothing.
void computeLevels(int nodeCount, const std::vector<std::pair<int, int>>& belowAbove, ContactLevels& out);

// Every finite node is in exactly one island (one without pairs forms an island of its own).
struct Islands {
  std::vector<int> islandOf;              // per node; -1 for infinite-mass nodes
  std::vector<std::vector<int>> members;  // per island, ascending; islands ordered by first member
  std::vector<std::vector<int>> pairs;    // per island: indices into `pairs` given, ascending
};

// Groups pairs (i, j) by connectivity through finite-mass nodes. A pair between an infinite-mass
// node and a finite one belongs to the finite node's island; a pair of two infinite-mass nodes
// belongs to no island.
Islands computeIslands(int nodeCount, const std::vector<std::pair<int, int>>& pairs,
                       const std::vector<char>& isInfinite);
// The same into `out`, reusing its storage (as computeLevels above).
void computeIslands(int nodeCount, const std::vector<std::pair<int, int>>& pairs, const std::vector<char>& isInfinite,
                    Islands& out);

}  // namespace monolith::solvers::contact
