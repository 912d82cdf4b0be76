#include "solvers/parallel/ordered_tasks.h"

#include <tbb/concurrent_queue.h>
#include <tbb/parallel_for.h>
#include <tbb/partitioner.h>

#include <algorithm>
#include <memory>
#include <stdexcept>
#include <thread>

namespace monolith::solvers::parallel {

void OrderedTasks::reset(int objectCount) {
  lastWriter_.assign(static_cast<std::size_t>(objectCount), -1);
  readers_.resize(static_cast<std::size_t>(objectCount));
  for (auto& r : readers_) r.clear();
  depth_.clear();
  predecessorCount_.clear();
  edges_.clear();
  criticalPath_ = 0;
}

void OrderedTasks::addDependency(int from, std::vector<int>& deps) const {
  if (from < 0) return;
  if (std::find(deps.begin(), deps.end(), from) == deps.end()) deps.push_back(from);
}

int OrderedTasks::add(std::initializer_list<int> writes, std::initializer_list<int> reads) {
  return add(writes.begin(), static_cast<int>(writes.size()), reads.begin(), static_cast<int>(reads.size()));
}

int OrderedTasks::add(const int* writes, int writeCount, const int* reads, int readCount) {
  const int k = size();
  thread_local std::vector<int> deps;
  deps.clear();
  const int objects = static_cast<int>(lastWriter_.size());
  auto check = [&](int o) {
    if (o < 0 || o >= objects) throw std::out_of_range("OrderedTasks: object index out of range");
  };
  for (int i = 0; i < writeCount; ++i) {
    const int o = writes[i];
    check(o);
    addDependency(lastWriter_[o], deps);
    for (int r : readers_[o]) addDependency(r, deps);
  }
  for (int i = 0; i < readCount; ++i) {
    check(reads[i]);
    addDependency(lastWriter_[reads[i]], deps);
  }
  // Record this task's accesses only after collecting its dependencies, so an object both
  // read and written (or named twice) makes no self-edge.
  for (int i = 0; i < writeCount; ++i) {
    lastWriter_[writes[i]] = k;
    readers_[writes[i]].clear();
  }
  for (int i = 0; i < readCount; ++i) {
    auto& r = readers_[reads[i]];
    if (lastWriter_[reads[i]] != k && (r.empty() || r.back() != k)) r.push_back(k);
  }
  int depth = 1;
  for (int p : deps) {
    depth = std::max(depth, depth_[p] + 1);
    edges_.emplace_back(p, k);
  }
  depth_.push_back(depth);
  predecessorCount_.push_back(static_cast<int>(deps.size()));
  criticalPath_ = std::max(criticalPath_, depth);
  return k;
}

std::vector<int> OrderedTasks::predecessors(int k) const {
  std::vector<int> result;
  for (const auto& [from, to] : edges_)
    if (to == k) result.push_back(from);
  std::sort(result.begin(), result.end());
  return result;
}

void OrderedTasks::run(const std::function<void(int)>& task) {
  const int n = size();
  const int threads = tbb::this_task_arena::max_concurrency();
  const bool share = threads > 1 && n >= kMinimumTasks && n >= kMinimumParallelism * criticalPath_;
  if (!share) {
    for (int k = 0; k < n; ++k) task(k);
    return;
  }
  runParallel(task, threads);
}

void OrderedTasks::runParallel(const std::function<void(int)>& task, int threads) {
  const int n = size();
  // Successors in compressed rows, in the order the edges were added (ascending successor).
  std::vector<int> start(static_cast<std::size_t>(n) + 1, 0), successors(edges_.size());
  for (const auto& e : edges_) ++start[e.first + 1];
  for (int k = 0; k < n; ++k) start[k + 1] += start[k];
  {
    std::vector<int> fill(start.begin(), start.end() - 1);
    for (const auto& e : edges_) successors[fill[e.first]++] = e.second;
  }
  std::unique_ptr<std::atomic<int>[]> pending(new std::atomic<int>[n]);
  tbb::concurrent_queue<int> ready;
  for (int k = 0; k < n; ++k) {
    pending[k].store(predecessorCount_[k], std::memory_order_relaxed);
    if (predecessorCount_[k] == 0) ready.push(k);
  }
  std::atomic<int> done{0};
  std::atomic<bool> failed{false};
  std::exception_ptr error;
  std::atomic_flag errorTaken = ATOMIC_FLAG_INIT;

  // Each worker takes a ready task, runs it, and releases its successors: the first one that
  // becomes ready it runs next itself (a chain stays on one thread, no queue traffic), the
  // others go to the queue. A worker with nothing ready waits for the tasks under way; it is
  // never waiting on itself, since the earliest unfinished task always has its predecessors
  // done. A single worker therefore finishes the whole run if the other thread never joins.
  auto worker = [&] {
    int next = -1, idle = 0;
    while (!failed.load(std::memory_order_relaxed)) {
      if (next < 0 && !ready.try_pop(next)) {
        if (done.load(std::memory_order_acquire) == n) return;
        if (++idle > 64) std::this_thread::yield();
        continue;
      }
      idle = 0;
      try {
        task(next);
      } catch (...) {
        if (!errorTaken.test_and_set()) error = std::current_exception();
        failed.store(true);
        return;
      }
      int follow = -1;
      for (int s = start[next]; s < start[next + 1]; ++s) {
        const int succ = successors[s];
        if (pending[succ].fetch_sub(1, std::memory_order_acq_rel) == 1) {
          if (follow < 0) follow = succ;
          else ready.push(succ);
        }
      }
      done.fetch_add(1, std::memory_order_acq_rel);
      next = follow;
    }
  };
  tbb::parallel_for(
      0, threads, 1, [&](int) { worker(); }, tbb::simple_partitioner());
  if (error) std::rethrow_exception(error);
}

}  // namespace monolith::solvers::parallel
