#include "solvers/parallel/ordered_tasks.h"

#include <tbb/task_arena.h>
#include <tbb/task_group.h>

#include <algorithm>
#include <atomic>
#include <memory>
#include <stdexcept>

namespace monolith::solvers::parallel {

void OrderedTasks::reset(int objectCount, int grain, bool track) {
  if (grain < 1) throw std::invalid_argument("OrderedTasks: grain must be at least 1");
  track_ = track;
  grain_ = grain;
  size_ = 0;
  depth_.clear();
  predecessorCount_.clear();
  edges_.clear();
  dependedOnBy_.clear();
  criticalPath_ = 0;
  if (!track) return;
  lastWriter_.assign(static_cast<std::size_t>(objectCount), -1);
  readers_.resize(static_cast<std::size_t>(objectCount));
  for (auto& r : readers_) r.clear();
}

// Makes the open (last) block wait for `block`, unless that is itself or already a predecessor
// (marked per block, so that recording a task costs the same however many predecessors its block
// has: the recording runs on one thread before the tasks are shared).
void OrderedTasks::depend(int block) {
  const int open = blocks() - 1;
  if (block < 0 || block == open || dependedOnBy_[block] == open) return;
  dependedOnBy_[block] = open;
  edges_.emplace_back(block, open);
  ++predecessorCount_[open];
  depth_[open] = std::max(depth_[open], depth_[block] + 1);
  criticalPath_ = std::max(criticalPath_, depth_[open]);
}

int OrderedTasks::add(std::initializer_list<int> writes, std::initializer_list<int> reads) {
  return add(writes.begin(), static_cast<int>(writes.size()), reads.begin(), static_cast<int>(reads.size()));
}

int OrderedTasks::add(const int* writes, int writeCount, const int* reads, int readCount) {
  const int k = size_++;
  if (!track_) {
    criticalPath_ = size_;
    return k;
  }
  const int objects = static_cast<int>(lastWriter_.size());
  for (int i = 0; i < writeCount; ++i)
    if (writes[i] < 0 || writes[i] >= objects) throw std::out_of_range("OrderedTasks: object index out of range");
  for (int i = 0; i < readCount; ++i)
    if (reads[i] < 0 || reads[i] >= objects) throw std::out_of_range("OrderedTasks: object index out of range");
  if (k % grain_ == 0) {  // a new block
    depth_.push_back(1);
    predecessorCount_.push_back(0);
    dependedOnBy_.push_back(-1);
    criticalPath_ = std::max(criticalPath_, 1);
  }
  const int block = blocks() - 1;
  for (int i = 0; i < writeCount; ++i) {
    const int o = writes[i];
    depend(lastWriter_[o]);
    for (int r : readers_[o]) depend(r);
  }
  for (int i = 0; i < readCount; ++i) depend(lastWriter_[reads[i]]);
  // Recorded after the dependencies are collected, and as blocks: accesses within one block
  // make no edges (an object both read and written, or named twice, makes none either).
  for (int i = 0; i < writeCount; ++i) {
    lastWriter_[writes[i]] = block;
    readers_[writes[i]].clear();
  }
  for (int i = 0; i < readCount; ++i) {
    auto& r = readers_[reads[i]];
    if (lastWriter_[reads[i]] != block && (r.empty() || r.back() != block)) r.push_back(block);
  }
  return k;
}

std::vector<int> OrderedTasks::predecessors(int block) const {
  std::vector<int> result;
  for (const auto& [from, to] : edges_)
    if (to == block) result.push_back(from);
  std::sort(result.begin(), result.end());
  return result;
}

void OrderedTasks::run(const std::function<void(int)>& task) {
  const int n = size();
  const int threads = tbb::this_task_arena::max_concurrency();
  const bool share =
      track_ && threads > 1 && blocks() >= kMinimumBlocks && blocks() >= kMinimumParallelism * criticalPath_;
  if (!share) {
    for (int k = 0; k < n; ++k) task(k);
    return;
  }
  runParallel(task);
}

void OrderedTasks::runParallel(const std::function<void(int)>& task) {
  const int n = blocks();
  // Successors in compressed rows, in the order the edges were added (ascending successor).
  std::vector<int> start(static_cast<std::size_t>(n) + 1, 0), successors(edges_.size());
  for (const auto& e : edges_) ++start[e.first + 1];
  for (int k = 0; k < n; ++k) start[k + 1] += start[k];
  {
    std::vector<int> fill(start.begin(), start.end() - 1);
    for (const auto& e : edges_) successors[fill[e.first]++] = e.second;
  }
  std::unique_ptr<std::atomic<int>[]> pending(new std::atomic<int>[n]);
  for (int k = 0; k < n; ++k) pending[k].store(predecessorCount_[k], std::memory_order_relaxed);

  // A block runs as a TBB task once its last predecessor has finished (the acquire-release
  // count hands that predecessor's writes to it). Of the successors it releases, it runs the
  // first itself, next (a chain stays on one thread and in its cache); the others are spawned,
  // and oneTBB's work stealing runs them where a thread is free, newest first on the thread that
  // spawned them. No thread ever waits on a flag: a blocked thread steals work instead. (A
  // shared ready queue with spinning workers was measured 2-4 % slower on the pyramid and the
  // pours, docs/benchmarks.md.) An exception cancels the group and is rethrown by wait().
  tbb::task_group group;
  std::function<void(int)> runFrom = [&](int block) {
    while (block >= 0) {
      const int end = std::min(size_, (block + 1) * grain_);
      for (int k = block * grain_; k < end; ++k) task(k);
      int next = -1;
      for (int s = start[block]; s < start[block + 1]; ++s) {
        const int successor = successors[s];
        if (pending[successor].fetch_sub(1, std::memory_order_acq_rel) != 1) continue;
        if (next < 0) next = successor;
        else group.run([&runFrom, successor] { runFrom(successor); });
      }
      block = next;
    }
  };
  for (int k = 0; k < n; ++k)
    if (predecessorCount_[k] == 0) group.run([&runFrom, k] { runFrom(k); });
  group.wait();
}

}  // namespace monolith::solvers::parallel
