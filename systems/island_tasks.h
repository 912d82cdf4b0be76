#pragma once
// The island/task layer of the rigid contact stages. No physics here: which island each body
// belongs to, and how a sequence of updates over one island's bodies is recorded and run.
//
// Islands (solvers/contact/contact_graph.h: bodies connected through bodies of finite mass) share
// no body that a stage changes, so they run at once (forEachIsland). Inside an island a stage's
// updates are recorded in the order of the sequential sweep, each declaring the bodies it changes
// (those of finite mass) and those it only reads (those frozen so far, per island member), and
// run with solvers/parallel/ordered_tasks: each update sees exactly the bodies the sequential
// sweep gives it, so the result is bitwise that of one thread, while updates far apart in the
// sequence that share no body run at once. Bodies that no stage ever changes (static, kinematic,
// asleep) are not declared at all.
//
// What a task does is the caller's: it passes a runner, called as run(task) -> TaskCounts, when
// the tasks are run. On one thread, or for a sequence too short to be shared, the tasks run as
// they are recorded and nothing is tracked (OrderedTasks's `track`).
#include <array>
#include <cstddef>
#include <tuple>
#include <utility>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/partitioner.h>
#include <tbb/task_arena.h>

#include "solvers/contact/contact_graph.h"
#include "solvers/parallel/ordered_tasks.h"

namespace monolith {

// What one task reports: impulses applied, clamps that acted and the energy they changed.
// Summed over a sequence in its order, so that the sums do not depend on the thread count.
struct TaskCounts {
  int impulses = 0, clamps = 0;
  double energyChange = 0;
};

// One task's counts added to a sequence's sums, each where it is wanted (an energy change only
// where a clamp acted or the change is not zero, so that a sum of zeros stays exactly as it was).
inline void addTaskCounts(const TaskCounts& c, int* impulseSum, int* clampsOut, double* energyOut) {
  if (impulseSum) *impulseSum += c.impulses;
  if (clampsOut) *clampsOut += c.clamps;
  if (energyOut && (c.clamps != 0 || c.energyChange != 0)) *energyOut += c.energyChange;
}

// One island's recorded tasks. Kept per island slot from step to step (its storage is reused).
template <class Task>
struct TaskSequence {
  solvers::parallel::OrderedTasks order;
  std::vector<Task> tasks;
  std::vector<int> lists;          // index lists the tasks refer to by range (the caller's)
  std::vector<char> frozen;        // per island member: declared read-only from here on
  std::vector<TaskCounts> counts;  // per task, when the tasks run after being recorded
  double* energyOut = nullptr;     // the caller's sums, added to in task order
  int* clampsOut = nullptr;
  int impulseSum = 0;              // when the tasks run as they are recorded
  // The caller's mark that the recorded tasks may be run again as they are (runAgain).
  bool reusable = false;
};

template <class Task>
class IslandTasks {
 public:
  using Sequence = TaskSequence<Task>;

  // The step's islands and, per body, whether no stage ever changes it. Both are kept by
  // reference (the contact workspace's members) until the next call.
  void setIslands(const solvers::contact::Islands& islands, const std::vector<char>& immovable) {
    islands_ = &islands;
    immovable_ = &immovable;
    memberIndex_.assign(immovable.size(), -1);
    for (const auto& members : islands.members)
      for (std::size_t k = 0; k < members.size(); ++k) memberIndex_[members[k]] = static_cast<int>(k);
    if (sequences_.size() < islands.members.size()) sequences_.resize(islands.members.size());
  }

  // Body's position among its island's members; -1 for a body in no island.
  int memberIndex(int body) const { return memberIndex_[body]; }

  // Runs f(island) for every island at once (bodies of different islands are disjoint, so the
  // results do not depend on the thread count).
  template <class F>
  void forEachIsland(F&& f) const {
    const std::size_t n = islands_ ? islands_->members.size() : 0;
    if (n == 0) return;
    tbb::parallel_for(
        tbb::blocked_range<std::size_t>(0, n, 1),
        [&](const tbb::blocked_range<std::size_t>& r) {
          for (std::size_t i = r.begin(); i != r.end(); ++i) f(static_cast<int>(i));
        },
        tbb::simple_partitioner());
  }

  // Resets `order` for an island's tasks, handed out in blocks of `grain`. `taskBound`: at most
  // how many tasks will be added. Dependencies are tracked only where they can be used: with more
  // than one thread, more than one member, and room for the blocks OrderedTasks::run needs to
  // share the sequence (recording the dependencies of tasks that run in order anyway cost a
  // falling 250-sphere pour a fifth of its step on 2 threads).
  void startOrder(solvers::parallel::OrderedTasks& order, int island, std::size_t taskBound, int grain) const {
    const int members = static_cast<int>(islands_->members[island].size());
    const bool shareable = taskBound >= static_cast<std::size_t>(solvers::parallel::OrderedTasks::kMinimumBlocks) *
                                            static_cast<std::size_t>(grain);
    order.reset(members, grain, members > 1 && shareable && tbb::this_task_arena::max_concurrency() > 1);
  }

  // Appends to `order` a task touching the given bodies: those frozen (per island member,
  // `frozen`) as read, the others of finite mass as written, immovable ones not at all.
  void addOrdered(solvers::parallel::OrderedTasks& order, const std::vector<char>& frozen, const int* touched,
                  int count) const {
    if (!order.tracking()) {
      order.add(nullptr, 0, nullptr, 0);
      return;
    }
    // Room for every touched body, filled by index (this runs once per recorded task, on the
    // recording thread, whose time the other thread mostly waits for: the usual few bodies fit
    // on the stack, with no thread-local lookup).
    std::array<int, kTouchedOnStack> writesOnStack, readsOnStack;
    int* writes = writesOnStack.data();
    int* reads = readsOnStack.data();
    if (count > kTouchedOnStack) std::tie(writes, reads) = heapBuffers(count);
    int writeCount = 0, readCount = 0;
    for (int i = 0; i < count; ++i) {
      if ((*immovable_)[touched[i]]) continue;
      const int local = memberIndex_[touched[i]];
      if (frozen[local]) reads[readCount++] = local;
      else writes[writeCount++] = local;
    }
    order.add(writes, writeCount, reads, readCount);
  }

  // The island's sequence, started anew (no tasks, nothing frozen); the sums go to the caller's
  // `energyOut` and `clampsOut` (either may be null).
  Sequence& start(int island, std::size_t taskBound, int grain, double* energyOut, int* clampsOut) {
    Sequence& s = sequences_[island];
    s.energyOut = energyOut;
    s.clampsOut = clampsOut;
    s.impulseSum = 0;  // the per-task slots are sized by run
    startOrder(s.order, island, taskBound, grain);
    s.reusable = false;
    s.tasks.clear();
    s.lists.clear();
    s.frozen.assign(islands_->members[island].size(), 0);
    return s;
  }
  // The island's sequence as last recorded.
  Sequence& sequence(int island) { return sequences_[island]; }

  // Whether a body is of infinite mass at the point of the sequence being recorded: immovable,
  // or declared frozen.
  bool fixedIn(const Sequence& s, int body) const {
    return (*immovable_)[body] || (memberIndex_[body] >= 0 && s.frozen[memberIndex_[body]]);
  }
  // Declares a member frozen from the point being recorded on.
  void markFrozen(Sequence& s, int body) const { s.frozen[memberIndex_[body]] = 1; }

  // Appends a task touching the given bodies (as addOrdered). Untracked, it runs at once: the
  // order is the same, and the caller records nothing that depends on what earlier tasks did.
  template <class Run>
  void add(Sequence& s, const Task& task, const int* touched, int count, Run&& run) {
    if (!s.order.tracking()) {
      addTaskCounts(run(task), &s.impulseSum, s.clampsOut, s.energyOut);
      return;
    }
    s.tasks.push_back(task);  // its result slot is sized once, by run
    addOrdered(s.order, s.frozen, touched, count);
  }

  // Runs the recorded tasks (unless they ran as they were recorded) and sums their counts in
  // sequence order. Returns the impulses applied.
  template <class Run>
  int run(Sequence& s, Run&& run) {
    if (!s.order.tracking()) return s.impulseSum;  // already run, as recorded
    s.counts.assign(s.tasks.size(), TaskCounts{});
    s.order.run([&](int k) {
      // Written only when not zero: most updates apply nothing, and neighbouring slots may
      // belong to tasks running on the other core.
      const TaskCounts c = run(s.tasks[k]);
      if (c.impulses != 0 || c.clamps != 0 || c.energyChange != 0) s.counts[k] = c;
    });
    int impulses = 0;
    for (const TaskCounts& c : s.counts) addTaskCounts(c, &impulses, s.clampsOut, s.energyOut);
    return impulses;
  }

 private:
  static constexpr int kTouchedOnStack = 32;
  // addOrdered's room for a task touching more than kTouchedOnStack bodies: this thread's.
  [[gnu::noinline]] static std::pair<int*, int*> heapBuffers(int count) {
    thread_local std::vector<int> writes, reads;
    if (writes.size() < static_cast<std::size_t>(count)) writes.resize(count), reads.resize(count);
    return {writes.data(), reads.data()};
  }

  const solvers::contact::Islands* islands_ = nullptr;
  const std::vector<char>* immovable_ = nullptr;
  std::vector<int> memberIndex_;
  std::vector<Sequence> sequences_;  // per island (islands are recorded and run at once)
};

}  // namespace monolith
