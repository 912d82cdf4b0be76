#pragma once
// A fixed sequence of small tasks run on several threads with bitwise the result of running them
// one after another (the Gauss-Seidel sweeps of the contact stages inside one island).
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
#include <functional>
#include <initializer_list>
#include <utility>
#include <vector>

namespace monolith::solvers::parallel {

class OrderedTasks {
 public:
  // Forgets all tasks. Objects are numbered 0 .. objectCount-1. Consecutive tasks are handed out
  // in blocks of `grain` (a block runs in order on one thread and waits for what any of its
  // tasks waits for): tiny tasks would otherwise cost more to hand over than to run. With
  // `track` false the tasks will run in order on the calling thread and add() records nothing
  // but their count (an arena of one thread, where the dependencies would only cost time).
  void reset(int objectCount, int grain = 1, bool track = true);

  // Appends a task; returns its position in the sequential order.
  int add(std::initializer_list<int> writes, std::initializer_list<int> reads = {});
  int add(const int* writes, int writeCount, const int* reads, int readCount);

  int size() const { return size_; }
  bool tracking() const { return track_; }
  // Blocks of tasks, and the longest chain of blocks that must run one after another;
  // blocks() / criticalPath() bounds the speed-up.
  int blocks() const { return static_cast<int>(depth_.size()); }
  int criticalPath() const { return criticalPath_; }
  // The blocks that block b waits for (its direct predecessors), ascending, for tests.
  std::vector<int> predecessors(int block) const;

  // Calls task(k) once for every task. Sequentially in order when the arena has one thread or
  // the sequence is too short or too chained to be worth sharing; otherwise on up to the
  // arena's threads, each block after its predecessors. An exception from a task stops the run
  // and is rethrown here (tasks already started finish first).
  void run(const std::function<void(int)>& task);

  // Below this many blocks, or with less than this much average parallelism
  // (blocks() / criticalPath()), run() stays sequential.
  static constexpr int kMinimumBlocks = 32;
  static constexpr double kMinimumParallelism = 1.25;

 private:
  void depend(int block);
  void runParallel(const std::function<void(int)>& task);

  std::vector<int> lastWriter_;            // per object: last block that writes it, or -1
  std::vector<std::vector<int>> readers_;  // per object: blocks reading it since that write
  std::vector<int> depth_;                 // per block: 1 + the deepest predecessor's depth
  std::vector<int> predecessorCount_;      // per block
  std::vector<std::pair<int, int>> edges_;  // (predecessor, successor) blocks, in order of adding
  std::vector<int> dependedOnBy_;          // per block: the last block that recorded it as a predecessor
  int criticalPath_ = 0;
  int size_ = 0;
  int grain_ = 1;
  bool track_ = true;
};

}  // namespace monolith::solvers::parallel
