// OrderedTasks (solvers/parallel/ordered_tasks.h): the dependency rule, and that a run on several
// threads gives bitwise the sequential result.
#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <atomic>
#include <cmath>
#include <random>
#include <stdexcept>
#include <vector>

#include "solvers/parallel/ordered_tasks.h"

using monolith::solvers::parallel::OrderedTasks;

TEST(OrderedTasks, EdgesFollowReadAfterWriteWriteAfterWriteAndWriteAfterRead) {
  OrderedTasks t;
  t.reset(4);
  t.add({0});        // 0: writes 0
  t.add({1});        // 1: writes 1 (independent of 0)
  t.add({2}, {0});   // 2: reads 0 after 0 wrote it
  t.add({3}, {0});   // 3: reads 0 too; two readers do not wait for each other
  t.add({0});        // 4: writes 0: after the writer 0 and both readers 2, 3
  t.add({1, 2});     // 5: after 1 (object 1) and 2 (object 2)
  t.add({3, 3}, {3});  // 6: an object named twice, and read and written: one edge, to 3
  t.add({}, {0});    // 7: reads 0 after its last writer 4
  EXPECT_TRUE(t.predecessors(0).empty());
  EXPECT_TRUE(t.predecessors(1).empty());
  EXPECT_EQ(t.predecessors(2), (std::vector<int>{0}));
  EXPECT_EQ(t.predecessors(3), (std::vector<int>{0}));
  EXPECT_EQ(t.predecessors(4), (std::vector<int>{0, 2, 3}));
  EXPECT_EQ(t.predecessors(5), (std::vector<int>{1, 2}));
  EXPECT_EQ(t.predecessors(6), (std::vector<int>{3}));
  EXPECT_EQ(t.predecessors(7), (std::vector<int>{4}));
  // Longest chain: 0 -> 2 -> 4 -> 7.
  EXPECT_EQ(t.criticalPath(), 4);
  EXPECT_THROW(t.add({4}), std::out_of_range);
}

namespace {

// A random sequence of non-commuting floating-point updates on a few hundred objects, like a
// Gauss-Seidel sweep: each task reads up to two objects and writes one or two. Returns the
// objects' final values after running the sequence on `threads` threads.
std::vector<double> runRandomSweep(int threads, unsigned seed, int* criticalPath = nullptr, int* size = nullptr) {
  constexpr int kObjects = 300, kTasks = 20000;
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int> pick(0, kObjects - 1);
  struct Op {
    int w0, w1, r;
  };
  std::vector<Op> ops;
  OrderedTasks order;
  order.reset(kObjects);
  for (int k = 0; k < kTasks; ++k) {
    // Mostly neighbouring objects, like bodies in contact, with some long-range ones.
    const int a = pick(rng);
    const int b = (rng() % 8 == 0) ? pick(rng) : (a + 1) % kObjects;
    const int r = (a + kObjects - 1) % kObjects;
    ops.push_back({a, b, r});
    order.add({a, b}, {r});
  }
  if (criticalPath) *criticalPath = order.criticalPath();
  if (size) *size = order.blocks();
  std::vector<double> x(kObjects);
  for (int i = 0; i < kObjects; ++i) x[i] = 1.0 + 1e-3 * i;
  tbb::task_arena arena(threads);
  arena.execute([&] {
    order.run([&](int k) {
      const Op& op = ops[k];
      const double coupling = std::sin(x[op.w0] - x[op.w1]) + 0.1 * x[op.r];
      x[op.w0] = 0.999 * x[op.w0] + 1e-3 * coupling;
      if (op.w1 != op.w0) x[op.w1] = 0.998 * x[op.w1] - 1e-3 * coupling * x[op.w0];
    });
  });
  return x;
}

}  // namespace

TEST(OrderedTasks, SeveralThreadsGiveBitwiseTheSequentialResult) {
  int path = 0, size = 0;
  const std::vector<double> one = runRandomSweep(1, 7, &path, &size);
  // The sequence must leave room for parallel work, or the test would only run it in order.
  ASSERT_GT(size, OrderedTasks::kMinimumParallelism * path);
  for (int repeat = 0; repeat < 10; ++repeat) {
    for (int threads : {2}) {
      const std::vector<double> many = runRandomSweep(threads, 7);
      ASSERT_EQ(one.size(), many.size());
      for (std::size_t i = 0; i < one.size(); ++i)
        ASSERT_EQ(one[i], many[i]) << "object " << i << ", " << threads << " threads, repeat " << repeat;
    }
  }
}

TEST(OrderedTasks, EveryTaskRunsOnceAfterItsPredecessors) {
  constexpr int kTasks = 5000;
  OrderedTasks order;
  order.reset(50);
  for (int k = 0; k < kTasks; ++k) order.add({k % 50}, {(k * 7) % 50});
  std::vector<std::atomic<int>> finished(kTasks);
  std::vector<int> runs(kTasks, 0);
  std::atomic<int> violations{0};
  tbb::task_arena arena(2);
  arena.execute([&] {
    order.run([&](int k) {
      for (int p : order.predecessors(k))
        if (finished[p].load() == 0) ++violations;
      ++runs[k];
      finished[k].store(1);
    });
  });
  EXPECT_EQ(violations.load(), 0);
  for (int k = 0; k < kTasks; ++k) ASSERT_EQ(runs[k], 1) << k;
}

TEST(OrderedTasks, AnExceptionFromATaskReachesTheCaller) {
  OrderedTasks order;
  order.reset(100);
  for (int k = 0; k < 1000; ++k) order.add({k % 100});
  tbb::task_arena arena(2);
  arena.execute([&] {
    EXPECT_THROW(order.run([](int k) {
      if (k == 517) throw std::runtime_error("task 517");
    }),
                 std::runtime_error);
  });
}
