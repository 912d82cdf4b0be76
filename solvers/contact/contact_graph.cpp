// Contact-graph levels and islands (Guendelman, Bridson & Fedkiw 2003; notes 1.6).
#include "solvers/contact/contact_graph.h"

#include <algorithm>
#include <functional>
#include <numeric>
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

void buildAdjacency(int nodeCount, const std::vector<std::pair<int, int>>& edges, Adjacency& adj,
                    std::vector<int>& fill) {
  adj.start.assign(static_cast<std::size_t>(nodeCount) + 1, 0);
  for (const auto& [from, to] : edges) ++adj.start[static_cast<std::size_t>(from) + 1];
  std::partial_sum(adj.start.begin(), adj.start.end(), adj.start.begin());
  adj.targets.resize(edges.size());
  fill.assign(adj.start.begin(), adj.start.end() - 1);
  for (const auto& [from, to] : edges) adj.targets[static_cast<std::size_t>(fill[from]++)] = to;
}

// Everything the two computations need besides their results, kept per thread: the graph is
// rebuilt every step (and by push-out), and once warm nothing here allocates.
struct GraphScratch {
  Adjacency adj, condensed;
  std::vector<int> fill, index, low, component, stack, smallest, inDegree, levelOfComponent, parent, islandOfRoot;
  std::vector<char> onStack;
  std::vector<std::pair<int, int>> frames, componentEdges, ready;
};
GraphScratch& graphScratch() {
  thread_local GraphScratch s;
  return s;
}

// Tarjan's strongly connected components with an explicit call stack, so that a chain of 10^5
// bodies cannot overflow the machine stack. Leaves the component of every node in s.component.
int stronglyConnectedComponents(int nodeCount, const Adjacency& adj, GraphScratch& s) {
  constexpr int kUnvisited = -1;
  std::vector<int>& index = s.index;
  std::vector<int>& low = s.low;
  std::vector<int>& component = s.component;
  std::vector<char>& onStack = s.onStack;
  std::vector<int>& stack = s.stack;
  std::vector<std::pair<int, int>>& frames = s.frames;  // (node, next adjacency position)
  index.assign(static_cast<std::size_t>(nodeCount), kUnvisited);
  low.assign(static_cast<std::size_t>(nodeCount), 0);
  component.assign(static_cast<std::size_t>(nodeCount), -1);
  onStack.assign(static_cast<std::size_t>(nodeCount), 0);
  stack.clear();
  frames.clear();
  int counter = 0;
  int componentCount = 0;

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
  return componentCount;
}

}  // namespace

void computeLevels(int nodeCount, const std::vector<std::pair<int, int>>& belowAbove, ContactLevels& result) {
  for (const auto& [below, above] : belowAbove) {
    checkNode(below, nodeCount);
    checkNode(above, nodeCount);
  }
  GraphScratch& s = graphScratch();
  buildAdjacency(nodeCount, belowAbove, s.adj, s.fill);
  const int componentCount = stronglyConnectedComponents(nodeCount, s.adj, s);
  const std::vector<int>& component = s.component;

  // Condensation: each cycle collapses to one node; name each by its smallest member so that
  // ties below are broken independently of Tarjan's visiting order.
  std::vector<int>& smallest = s.smallest;
  smallest.assign(static_cast<std::size_t>(componentCount), nodeCount);
  for (int v = 0; v < nodeCount; ++v) smallest[component[v]] = std::min(smallest[component[v]], v);
  std::vector<std::pair<int, int>>& componentEdges = s.componentEdges;
  componentEdges.clear();
  std::vector<int>& inDegree = s.inDegree;
  inDegree.assign(static_cast<std::size_t>(componentCount), 0);
  for (const auto& [below, above] : belowAbove) {
    const int from = component[below];
    const int to = component[above];
    if (from == to) continue;
    componentEdges.emplace_back(from, to);
    ++inDegree[to];
  }
  buildAdjacency(componentCount, componentEdges, s.condensed, s.fill);

  // Kahn's topological order from the bottom (nothing below), the ready component with the
  // smallest member first: each component is its own level (notes 1.6: levels are not merged).
  // The heap lives in the scratch vector (a min-heap on (smallest member, component)).
  using Entry = std::pair<int, int>;
  std::vector<Entry>& ready = s.ready;
  ready.clear();
  const auto later = std::greater<Entry>();
  auto push = [&](int c) {
    ready.emplace_back(smallest[c], c);
    std::push_heap(ready.begin(), ready.end(), later);
  };
  for (int c = 0; c < componentCount; ++c) {
    if (inDegree[c] == 0) push(c);
  }
  std::vector<int>& levelOfComponent = s.levelOfComponent;
  levelOfComponent.assign(static_cast<std::size_t>(componentCount), -1);
  int level = 0;
  while (!ready.empty()) {
    std::pop_heap(ready.begin(), ready.end(), later);
    const int c = ready.back().second;
    ready.pop_back();
    levelOfComponent[c] = level++;
    for (int p = s.condensed.start[c]; p < s.condensed.start[c + 1]; ++p) {
      const int next = s.condensed.targets[static_cast<std::size_t>(p)];
      if (--inDegree[next] == 0) push(next);
    }
  }

  result.levelOf.resize(static_cast<std::size_t>(nodeCount));
  result.nodes.resize(static_cast<std::size_t>(componentCount));
  for (auto& list : result.nodes) list.clear();  // keeps each list's storage
  for (int v = 0; v < nodeCount; ++v) {  // ascending, so each level's list is sorted
    const int l = levelOfComponent[component[v]];
    result.levelOf[v] = l;
    result.nodes[l].push_back(v);
  }
}

ContactLevels computeLevels(int nodeCount, const std::vector<std::pair<int, int>>& belowAbove) {
  ContactLevels result;
  computeLevels(nodeCount, belowAbove, result);
  return result;
}

void computeIslands(int nodeCount, const std::vector<std::pair<int, int>>& pairs, const std::vector<char>& isInfinite,
                    Islands& islands) {
  if (static_cast<int>(isInfinite.size()) != nodeCount) {
    throw std::invalid_argument("contact graph: isInfinite needs one entry per node");
  }
  GraphScratch& s = graphScratch();
  // Union-find over finite nodes; an infinite node (static ground) never joins two islands.
  std::vector<int>& parent = s.parent;
  parent.resize(static_cast<std::size_t>(nodeCount));
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

  // The lists are cleared, not freed: their storage carries over to the next call.
  islands.islandOf.assign(static_cast<std::size_t>(nodeCount), -1);
  std::size_t count = 0;
  std::vector<int>& islandOfRoot = s.islandOfRoot;
  islandOfRoot.assign(static_cast<std::size_t>(nodeCount), -1);
  for (int v = 0; v < nodeCount; ++v) {  // ascending: islands come ordered by first member
    if (isInfinite[v]) continue;
    const int root = find(v);
    if (islandOfRoot[root] < 0) {
      islandOfRoot[root] = static_cast<int>(count++);
      if (islands.members.size() < count) islands.members.emplace_back();
      islands.members[count - 1].clear();
    }
    islands.islandOf[v] = islandOfRoot[root];
    islands.members[islandOfRoot[root]].push_back(v);
  }
  islands.members.resize(count);
  islands.pairs.resize(count);
  for (auto& list : islands.pairs) list.clear();
  for (std::size_t p = 0; p < pairs.size(); ++p) {
    const auto& [a, b] = pairs[p];
    const int island = isInfinite[a] ? islands.islandOf[b] : islands.islandOf[a];
    if (island >= 0) islands.pairs[island].push_back(static_cast<int>(p));
  }
}

Islands computeIslands(int nodeCount, const std::vector<std::pair<int, int>>& pairs,
                       const std::vector<char>& isInfinite) {
  Islands islands;
  computeIslands(nodeCount, pairs, isInfinite, islands);
  return islands;
}

}  // namespace monolith::solvers::contact
