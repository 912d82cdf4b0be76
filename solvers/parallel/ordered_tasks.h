#pragma once
// A fixed sequence of small tasks run on several threads with bitwise the result of running them
// one after another (issue 3: the Gauss-Seidel sweeps of the contact stages inside one island).
//
// Each task declares the objects it may change (writes) and those it only looks at (reads).
// Task k waits for every earlier task that writes an object k touches (read-after-write,
// write-after-write) and for every earlier task that reads an object k writes
// (write-after-read) -- the rule of a task graph built from declared accesses, applied to single
// solves instead of whole systems. Two tasks that may run at once then touch disjoint state, and
// every task sees exactly the state the sequential order gives it. The outcome is the
// sequential one whatever the thread count or the scheduling; parallelism comes from tasks far
// apart in the sequence that share no object (the far side of a pile, the next row of a
// pyramid while the row below is still being swept).
//
// Tasks must not touch undeclared shared state; objects that no task writes (static bodies)
// need not be declared.
#include <tbb/task_arena.h>

#include <atomic>
#include <exception>
#include <functional>
#include <initializer_list>
#include <vector>

namespace monolith::solvers::parallel {

class OrderedTasks {
 public:
  // Forgets all tasks. Objects are numbered 0 .. objectCount-1.
  void reset(int objectCount);

  // Appends a task; returns its position in the sequential order.
  int add(std::initializer_list<int> writes, std::initializer_list<int> reads = {});
  int add(const int* writes, int writeCount, const int* reads, int readCount);

  int size() const { return static_cast<int>(depth_.size()); }
  // The longest chain of tasks that must run one after another; size() / criticalPath() bounds
  // the speed-up.
  int criticalPath() const { return criticalPath_; }
  // The tasks that task k waits for (its direct predecessors), for tests.
  std::vector<int> predecessors(int k) const;

  // Calls task(k) once for every task. Sequentially in order when the arena has one thread or
  // the sequence is too short or too chained to be worth sharing; otherwise on up to the
  // arena's threads, each task after its predecessors. An exception from a task stops the run
  // and is rethrown here (tasks already started finish first).
  void run(const std::function<void(int)>& task);

  // Below this many tasks, or with less than this much average parallelism
  // (size() / criticalPath()), run() stays sequential: the hand-over costs ~0.1 us per task.
  static constexpr int kMinimumTasks = 32;
  static constexpr double kMinimumParallelism = 1.25;

 private:
  void addDependency(int from, std::vector<int>& deps) const;
  void runParallel(const std::function<void(int)>& task, int threads);

  std::vector<int> lastWriter_;               // per object: last task that writes it, or -1
  std::vector<std::vector<int>> readers_;     // per object: tasks reading it since that write
  std::vector<int> depth_;                    // per task: 1 + the deepest predecessor's depth
  std::vector<int> predecessorCount_;         // per task
  std::vector<std::pair<int, int>> edges_;    // (predecessor, successor), in order of adding
  int criticalPath_ = 0;
};

}  // namespace monolith::solvers::parallel
