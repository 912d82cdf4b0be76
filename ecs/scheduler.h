#pragma once
// Turns the systems a scene needs into a oneTBB flow graph (STYLE.md practice 3).
//  * Serial meaning: systems sorted by (stage, registration order). Every parallel run must
//    produce what this order produces.
//  * Edges: every system of a stage precedes every system of the next non-empty stage (stage
//    fences); inside a stage, system i precedes a later system j when they conflict
//    (i writes what j reads, i reads what j writes, or both write the same thing).
//  * Systems whose needed() is false are dropped before the graph is built.
// The graph runs inside a task_arena with the requested number of threads.
#include <array>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "ecs/system.h"

namespace monolith {

template <int d>
class Scheduler {
 public:
  Scheduler(std::vector<std::unique_ptr<System<d>>> candidates, const World<d>& world, int threads);
  ~Scheduler();
  Scheduler(const Scheduler&) = delete;
  Scheduler& operator=(const Scheduler&) = delete;

  // Scheduled systems in their serial order.
  const std::vector<System<d>*>& systems() const { return order_; }
  // Names of the candidate systems that were not scheduled (needed() == false).
  const std::vector<std::string>& skipped() const { return skipped_; }
  // Edges (from, to) as indices into systems().
  const std::vector<std::pair<int, int>>& edges() const { return edges_; }
  // True when `later` cannot start before `earlier` has finished (a path in the graph).
  bool ordered(int earlier, int later) const;
  int indexOf(const std::string& systemName) const;
  std::string dot() const;
  int threads() const { return threads_; }

  // Runs one step. Rethrows the first exception a system threw.
  void step(World<d>& world, StepContext& ctx);

  // Wall time of each stage in the last step (first start to last end of its systems).
  const std::array<double, static_cast<int>(Stage::Count)>& stageSeconds() const { return stageSeconds_; }

 private:
  struct Graph;
  std::vector<std::unique_ptr<System<d>>> owned_;
  std::vector<System<d>*> order_;
  std::vector<std::string> skipped_;
  std::vector<std::pair<int, int>> edges_;
  std::vector<std::vector<char>> reach_;  // reach_[i][j]: path i -> j
  int threads_;
  std::unique_ptr<Graph> graph_;
  std::array<double, static_cast<int>(Stage::Count)> stageSeconds_{};
};

// Read/write conflict rule (EnTT organizer): RAW, WAR, WAW.
bool systemsConflict(const std::vector<std::string>& readsA, const std::vector<std::string>& writesA,
                     const std::vector<std::string>& readsB, const std::vector<std::string>& writesB);

}  // namespace monolith
