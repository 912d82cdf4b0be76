// Contact-graph levels and islands (Guendelman, Bridson & Fedkiw 2003; notes 1.6).
#include "solvers/contact/contact_graph.h"

#include <algorithm>
#include <functional>
#include <numeric>
#include <queue>
#include <stdexcept>
#include <string>

namespace monolith::solvers::contact {

namespace {

void checkNode(int node, int nodeCount) {
  if (node < 0 || node >= nodeCount) {
    throw std::invalid_argument("contact graph: node " + std::to_string(node) + " outside [0, " +
                                std::to_string(nodeCount) + ")");
  }
}

// Compressed adjacency: the targets of node v are targets[start[v] .. start[v+1]).
struct Adjacency {
  std::vector<int> start;
  std::vector<int> targets;
};

Adjacency buildAdjacency(int nodeCount, const std::vector<std::pair<int, int>>& edges) {
  Adjacency adj;
  adj.start.assign(static_cast<std::size_t>(nodeCount) + 1, 0);
  for (const auto& [from, to] : edges) ++adj.start[static_cast<std::size_t>(from) + 1];
  std::partial_sum(adj.start.begin(), adj.start.end(), adj.start.begin());
  adj.targets.resize(edges.size());
  std::vector<int> fill(adj.start.begin(), adj.start.end() - 1);
  for (const auto& [from, to] : edges) adj.targets[static_cast<std::size_t>(fill[from]++)] = to;
  return adj;
}

// Tarjan's strongly connected components with an explicit call stack, so that a chain of 10^5
// bodies cannot overflow the machine stack. Returns the component of every node.
std::vector<int> stronglyConnectedComponents(int nodeCount, const Adjacency& adj,
                                             int& componentCount) {
  constexpr int kUnvisited = -1;
  std::vector<int> index(static_cast<std::size_t>(nodeCount), kUnvisited);
  std::vector<int> low(static_cast<std::size_t>(nodeCount), 0);
  std::vector<int> component(static_cast<std::size_t>(nodeCount), -1);
  std::vector<char> onStack(static_cast<std::size_t>(nodeCount), 0);
  std::vector<int> stack;
  std::vector<std::pair<int, int>> frames;  // (node, next adjacency position)
  int counter = 0;
  componentCount = 0;

  auto visit = [&](int v) {
    index[v] = low[v] = counter++;
    stack.push_back(v);
    onStack[v] = 1;
    frames.emplace_back(v, adj.start[v]);
  };
  for (int root = 0; root < nodeCount; ++root) {
    if (index[root] != kUnvisited) continue;
    visit(root);
    while (!frames.empty()) {
      const int v = frames.back().first;
      const int position = frames.back().second;
      if (position < adj.start[v + 1]) {
        ++frames.back().second;
        const int w = adj.targets[static_cast<std::size_t>(position)];
        if (index[w] == kUnvisited) {
          visit(w);
        } else if (onStack[w]) {
          low[v] = std::min(low[v], index[w]);
        }
        continue;
      }
      // All successors done: v closes a component if it is its root.
      if (low[v] == index[v]) {
        int w;
        do {
          w = stack.back();
          stack.pop_back();
          onStack[w] = 0;
          component[w] = componentCount;
        } while (w != v);
        ++componentCount;
      }
      frames.pop_back();
      if (!frames.empty()) {
        const int parent = frames.back().first;
        low[parent] = std::min(low[parent], low[v]);
      }
    }
  }
  return component;
}

}  // namespace

ContactLevels computeLevels(int nodeCount, const std::vector<std::pair<int, int>>& belowAbove) {
  for (const auto& [below, above] : belowAbove) {
    checkNode(below, nodeCount);
    checkNode(above, nodeCount);
  }
  const Adjacency adj = buildAdjacency(nodeCount, belowAbove);
  int componentCount = 0;
  const std::vector<int> component = stronglyConnectedComponents(nodeCount, adj, componentCount);

  // Condensation: each cycle collapses to one node; name each by its smallest member so that
  // ties below are broken independently of Tarjan's visiting order.
  std::vector<int> smallest(static_cast<std::size_t>(componentCount), nodeCount);
  for (int v = 0; v < nodeCount; ++v) smallest[component[v]] = std::min(smallest[component[v]], v);
  std::vector<std::pair<int, int>> componentEdges;
  componentEdges.reserve(belowAbove.size());
  std::vector<int> inDegree(static_cast<std::size_t>(componentCount), 0);
  for (const auto& [below, above] : belowAbove) {
    const int from = component[below];
    const int to = component[above];
    if (from == to) continue;
    componentEdges.emplace_back(from, to);
    ++inDegree[to];
  }
  const Adjacency condensed = buildAdjacency(componentCount, componentEdges);

  // Kahn's topological order from the bottom (nothing below), the ready component with the
  // smallest member first: each component is its own level (notes 1.6: levels are not merged).
  using Entry = std::pair<int, int>;  // (smallest member, component)
  std::priority_queue<Entry, std::vector<Entry>, std::greater<Entry>> ready;
  for (int c = 0; c < componentCount; ++c) {
    if (inDegree[c] == 0) ready.emplace(smallest[c], c);
  }
  std::vector<int> levelOfComponent(static_cast<std::size_t>(componentCount), -1);
  int level = 0;
  while (!ready.empty()) {
    const int c = ready.top().second;
    ready.pop();
    levelOfComponent[c] = level++;
    for (int p = condensed.start[c]; p < condensed.start[c + 1]; ++p) {
      const int next = condensed.targets[static_cast<std::size_t>(p)];
      if (--inDegree[next] == 0) ready.emplace(smallest[next], next);
    }
  }

  ContactLevels result;
  result.levelOf.resize(static_cast<std::size_t>(nodeCount));
  result.nodes.resize(static_cast<std::size_t>(componentCount));
  for (int v = 0; v < nodeCount; ++v) {  // ascending, so each level's list is sorted
    const int l = levelOfComponent[component[v]];
    result.levelOf[v] = l;
    result.nodes[l].push_back(v);
  }
  return result;
}

Islands computeIslands(int nodeCount, const std::vector<std::pair<int, int>>& pairs,
                       const std::vector<char>& isInfinite) {
  if (static_cast<int>(isInfinite.size()) != nodeCount) {
    throw std::invalid_argument("contact graph: isInfinite needs one entry per node");
  }
  // Union-find over finite nodes; an infinite node (static ground) never joins two islands.
  std::vector<int> parent(static_cast<std::size_t>(nodeCount));
  std::iota(parent.begin(), parent.end(), 0);
  auto find = [&parent](int v) {
    while (parent[v] != v) {
      parent[v] = parent[parent[v]];  // path halving
      v = parent[v];
    }
    return v;
  };
  for (const auto& [a, b] : pairs) {
    checkNode(a, nodeCount);
    checkNode(b, nodeCount);
    if (isInfinite[a] || isInfinite[b]) continue;
    const int ra = find(a);
    const int rb = find(b);
    if (ra != rb) parent[std::max(ra, rb)] = std::min(ra, rb);
  }

  Islands islands;
  islands.islandOf.assign(static_cast<std::size_t>(nodeCount), -1);
  std::vector<int> islandOfRoot(static_cast<std::size_t>(nodeCount), -1);
  for (int v = 0; v < nodeCount; ++v) {  // ascending: islands come ordered by first member
    if (isInfinite[v]) continue;
    const int root = find(v);
    if (islandOfRoot[root] < 0) {
      islandOfRoot[root] = static_cast<int>(islands.members.size());
      islands.members.emplace_back();
    }
    islands.islandOf[v] = islandOfRoot[root];
    islands.members[islandOfRoot[root]].push_back(v);
  }
  islands.pairs.resize(islands.members.size());
  for (std::size_t p = 0; p < pairs.size(); ++p) {
    const auto& [a, b] = pairs[p];
    const int island = isInfinite[a] ? islands.islandOf[b] : islands.islandOf[a];
    if (island >= 0) islands.pairs[island].push_back(static_cast<int>(p));
  }
  return islands;
}

}  // namespace monolith::solvers::contact
