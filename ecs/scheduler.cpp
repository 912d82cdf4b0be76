#include "ecs/scheduler.h"

#include <algorithm>
#include <chrono>
#include <exception>
#include <mutex>
#include <sstream>

#include <tbb/flow_graph.h>
#include <tbb/task_arena.h>

namespace monolith {

namespace {
bool intersects(const std::vector<std::string>& a, const std::vector<std::string>& b) {
  for (const auto& x : a)
    if (std::find(b.begin(), b.end(), x) != b.end()) return true;
  return false;
}
using Clock = std::chrono::steady_clock;
}  // namespace

bool systemsConflict(const std::vector<std::string>& readsA, const std::vector<std::string>& writesA,
                     const std::vector<std::string>& readsB, const std::vector<std::string>& writesB) {
  return intersects(writesA, readsB) || intersects(readsA, writesB) || intersects(writesA, writesB);
}

template <int d>
struct Scheduler<d>::Graph {
  tbb::task_arena arena;
  std::unique_ptr<tbb::flow::graph> graph;
  std::unique_ptr<tbb::flow::broadcast_node<tbb::flow::continue_msg>> start;
  std::vector<std::unique_ptr<tbb::flow::continue_node<tbb::flow::continue_msg>>> nodes;
  // Per-step run state the node bodies use.
  World<d>* world = nullptr;
  StepContext* ctx = nullptr;
  std::vector<Clock::time_point> begin, end;
  std::mutex errorMutex;
  std::exception_ptr error;
  explicit Graph(int threads) : arena(threads) {}
};

template <int d>
Scheduler<d>::Scheduler(std::vector<std::unique_ptr<System<d>>> candidates, const World<d>& world, int threads)
    : threads_(std::max(1, threads)) {
  for (auto& s : candidates) {
    if (s->needed(world)) {
      owned_.push_back(std::move(s));
    } else {
      skipped_.push_back(s->name());
    }
  }
  // Stable sort: registration order is kept inside a stage.
  std::stable_sort(owned_.begin(), owned_.end(),
                   [](const auto& a, const auto& b) { return a->stage() < b->stage(); });
  for (auto& s : owned_) order_.push_back(s.get());

  const int n = static_cast<int>(order_.size());
  std::vector<std::vector<std::string>> reads(n), writes(n);
  for (int i = 0; i < n; ++i) {
    reads[i] = order_[i]->reads();
    writes[i] = order_[i]->writes();
  }
  for (int j = 0; j < n; ++j) {
    const Stage sj = order_[j]->stage();
    // Stage fence: all systems of the closest earlier non-empty stage.
    Stage previous = Stage::Count;
    for (int i = j - 1; i >= 0; --i)
      if (order_[i]->stage() < sj) {
        previous = order_[i]->stage();
        break;
      }
    for (int i = 0; i < j; ++i) {
      const Stage si = order_[i]->stage();
      if ((si == previous) || (si == sj && systemsConflict(reads[i], writes[i], reads[j], writes[j])))
        edges_.emplace_back(i, j);
    }
  }
  reach_.assign(n, std::vector<char>(n, 0));
  for (int j = 0; j < n; ++j)  // edges go forward in the serial order: one pass suffices
    for (const auto& [a, b] : edges_)
      if (b == j) {
        reach_[a][j] = 1;
        for (int k = 0; k < n; ++k)
          if (reach_[k][a]) reach_[k][j] = 1;
      }

  graph_ = std::make_unique<Graph>(threads_);
  Graph& g = *graph_;
  g.begin.resize(n);
  g.end.resize(n);
  g.arena.execute([&] {
    g.graph = std::make_unique<tbb::flow::graph>();
    g.start = std::make_unique<tbb::flow::broadcast_node<tbb::flow::continue_msg>>(*g.graph);
    for (int i = 0; i < n; ++i) {
      g.nodes.push_back(std::make_unique<tbb::flow::continue_node<tbb::flow::continue_msg>>(
          *g.graph, [this, i](const tbb::flow::continue_msg&) {
            Graph& gg = *graph_;
            gg.begin[i] = Clock::now();
            {
              std::lock_guard<std::mutex> lock(gg.errorMutex);
              if (gg.error) {  // an earlier system failed: skip the rest of the step
                gg.end[i] = gg.begin[i];
                return;
              }
            }
            try {
              order_[i]->run(*gg.world, *gg.ctx);
            } catch (...) {
              std::lock_guard<std::mutex> lock(gg.errorMutex);
              if (!gg.error) gg.error = std::current_exception();
            }
            gg.end[i] = Clock::now();
          }));
    }
    std::vector<int> inDegree(n, 0);
    for (const auto& [a, b] : edges_) {
      tbb::flow::make_edge(*g.nodes[a], *g.nodes[b]);
      ++inDegree[b];
    }
    for (int i = 0; i < n; ++i)
      if (inDegree[i] == 0) tbb::flow::make_edge(*g.start, *g.nodes[i]);
  });
}

template <int d>
Scheduler<d>::~Scheduler() {
  if (graph_) {
    Graph& g = *graph_;
    g.arena.execute([&] {
      g.nodes.clear();
      g.start.reset();
      g.graph.reset();
    });
  }
}

template <int d>
bool Scheduler<d>::ordered(int earlier, int later) const {
  return reach_.at(earlier).at(later) != 0;
}

template <int d>
int Scheduler<d>::indexOf(const std::string& systemName) const {
  for (int i = 0; i < static_cast<int>(order_.size()); ++i)
    if (order_[i]->name() == systemName) return i;
  return -1;
}

template <int d>
std::string Scheduler<d>::dot() const {
  std::ostringstream out;
  out << "digraph step {\n  rankdir=LR;\n";
  for (int i = 0; i < static_cast<int>(order_.size()); ++i)
    out << "  n" << i << " [label=\"" << order_[i]->name() << "\\n(" << stageName(order_[i]->stage()) << ")\"];\n";
  for (const auto& [a, b] : edges_) out << "  n" << a << " -> n" << b << ";\n";
  out << "}\n";
  return out.str();
}

template <int d>
void Scheduler<d>::step(World<d>& world, StepContext& ctx) {
  Graph& g = *graph_;
  g.world = &world;
  g.ctx = &ctx;
  g.error = nullptr;
  g.arena.execute([&] {
    g.start->try_put(tbb::flow::continue_msg());
    g.graph->wait_for_all();
  });
  stageSeconds_.fill(0.0);
  for (int s = 0; s < static_cast<int>(Stage::Count); ++s) {
    Clock::time_point first = Clock::time_point::max(), last = Clock::time_point::min();
    for (int i = 0; i < static_cast<int>(order_.size()); ++i) {
      if (static_cast<int>(order_[i]->stage()) != s) continue;
      first = std::min(first, g.begin[i]);
      last = std::max(last, g.end[i]);
    }
    if (first < last) stageSeconds_[s] = std::chrono::duration<double>(last - first).count();
  }
  if (g.error) std::rethrow_exception(g.error);
}

template class Scheduler<2>;
template class Scheduler<3>;

}  // namespace monolith
