// Broad phase: pairs of overlapping world boxes, by sweep and prune or by FCL's dynamic
// AABB tree. Both report exactly the pairs of closed boxes that overlap (every candidate is
// re-checked on the caller's boxes), sorted, so they agree with each other and with brute force.
//
// Unbounded boxes (a half-space's +-1e30 box) overlap everything and would make one sweep
// interval or one tree node cover the whole scene, so they stay out of the sweep/tree and are
// checked against every box directly; the scene has a handful of them (ground, walls).
#include <fcl/broadphase/broadphase_dynamic_AABB_tree.h>
#include <fcl/geometry/shape/box.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/partitioner.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <string>

#include "solvers/collision/broad_phase.h"

namespace monolith::solvers::collision {

namespace {

// A box reaching beyond this is treated as unbounded (scene coordinates are far smaller).
constexpr double kUnboundedExtent = 1e20;
// 2-D boxes become 3-D slabs of this half thickness for FCL's tree.
constexpr double kSlabHalfThickness = 1.0;

template <int d>
bool isUnbounded(const Eigen::AlignedBox<double, d>& b) {
  return !((b.min().array() > -kUnboundedExtent).all() && (b.max().array() < kUnboundedExtent).all());
}

// Closed boxes: touching counts.
template <int d>
bool touch(const Eigen::AlignedBox<double, d>& a, const Eigen::AlignedBox<double, d>& b) {
  for (int i = 0; i < d; ++i)
    if (a.min()[i] > b.max()[i] || b.min()[i] > a.max()[i]) return false;
  return true;
}

// An FCL collision object whose world AABB is set directly: the tree only needs boxes, and
// copying the caller's bounds exactly keeps FCL from missing a pair of merely touching boxes.
class BoxProxy : public fcl::CollisionObjectd {
 public:
  explicit BoxProxy(const std::shared_ptr<fcl::CollisionGeometryd>& placeholder) : fcl::CollisionObjectd(placeholder) {}
  void setBounds(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi, int index) {
    aabb.min_ = lo;
    aabb.max_ = hi;
    setUserData(reinterpret_cast<void*>(static_cast<std::intptr_t>(index)));
  }
  static int indexOf(const fcl::CollisionObjectd* o) {
    return static_cast<int>(reinterpret_cast<std::intptr_t>(o->getUserData()));
  }
};

}  // namespace

template <int d>
struct BroadPhase<d>::Impl {
  using Box = Eigen::AlignedBox<double, d>;
  std::vector<int> bounded, unbounded;
  // Sweep and prune: the bounded boxes copied contiguously in sweep order, so that the inner loop
  // streams through memory instead of chasing indices.
  struct Entry {
    std::array<double, d> lo, hi;
    int index;
    char flag;
  };
  std::vector<Entry> entries;
  // FCL dynamic AABB tree over reused proxies: rebuilt (bottom-up) when the set of bounded boxes
  // changes, refitted (FCL's incremental update) when only their bounds moved.
  std::shared_ptr<fcl::CollisionGeometryd> placeholder = std::make_shared<fcl::Boxd>(1, 1, 1);
  std::vector<std::unique_ptr<BoxProxy>> proxies;
  std::vector<fcl::CollisionObjectd*> registered;
  std::vector<int> registeredIndices;
  fcl::DynamicAABBTreeCollisionManagerd manager;
  // sortPairs' buckets and its output.
  std::vector<int> bucketStart, bucketNext;
  std::vector<std::pair<int, int>> sorted;

  // The pairs (i < j, all below n) sorted as std::sort sorts them (by i, then j): counted into
  // one bucket per i, each bucket then sorted on its own. A pour's pass finds thousands of
  // pairs in the tree's order, and sorting them whole took about a third of the pass.
  void sortPairs(std::vector<std::pair<int, int>>& pairs, int n) {
    bucketStart.assign(static_cast<std::size_t>(n) + 1, 0);
    for (const auto& p : pairs) ++bucketStart[p.first + 1];
    for (int i = 0; i < n; ++i) bucketStart[i + 1] += bucketStart[i];
    bucketNext.assign(bucketStart.begin(), bucketStart.end() - 1);
    sorted.resize(pairs.size());
    for (const auto& p : pairs) sorted[bucketNext[p.first]++] = p;
    for (int i = 0; i < n; ++i)
      if (bucketStart[i + 1] - bucketStart[i] > 1)
        std::sort(sorted.begin() + bucketStart[i], sorted.begin() + bucketStart[i + 1]);
    pairs.swap(sorted);
  }

  // What the FCL callback needs.
  struct Context {
    const std::vector<Box>* boxes;
    const std::vector<char>* flags;
    std::vector<std::pair<int, int>>* pairs;
  };

  static bool bothFlagged(const std::vector<char>& flags, int i, int j) {
    return !flags.empty() && flags[i] && flags[j];
  }

  static void add(int i, int j, std::vector<std::pair<int, int>>& pairs) { pairs.push_back({std::min(i, j), std::max(i, j)}); }

  void sweepAndPrune(const std::vector<Box>& boxes, const std::vector<char>& flags, std::vector<std::pair<int, int>>& pairs) {
    // Sweep along the axis on which the box centres spread most: fewest false candidates.
    int axis = 0;
    double bestSpread = -1;
    for (int k = 0; k < d; ++k) {
      double sum = 0, sum2 = 0;
      for (int i : bounded) {
        const double c = 0.5 * (boxes[i].min()[k] + boxes[i].max()[k]);
        sum += c;
        sum2 += c * c;
      }
      const double n = std::max<double>(1, bounded.size());
      const double spread = sum2 / n - (sum / n) * (sum / n);
      if (spread > bestSpread) {
        bestSpread = spread;
        axis = k;
      }
    }
    entries.clear();
    for (int i : bounded) {
      Entry e;
      for (int k = 0; k < d; ++k) {
        e.lo[k] = boxes[i].min()[k];
        e.hi[k] = boxes[i].max()[k];
      }
      e.index = i;
      e.flag = flags.empty() ? 0 : flags[i];
      entries.push_back(e);
    }
    std::sort(entries.begin(), entries.end(), [axis](const Entry& a, const Entry& b) {
      return a.lo[axis] != b.lo[axis] ? a.lo[axis] < b.lo[axis] : a.index < b.index;
    });
    const int m = static_cast<int>(entries.size());
    for (int p = 0; p < m; ++p) {
      const Entry& e = entries[p];
      const double hi = e.hi[axis];
      for (int q = p + 1; q < m && entries[q].lo[axis] <= hi; ++q) {
        const Entry& f = entries[q];
        // Without short-circuits: most candidates fail on some axis, unpredictably which, while
        // the combined test is almost always false, which the branch predictor gets right.
        bool overlap = !(e.flag & f.flag);
        for (int k = 0; k < d; ++k) overlap &= (e.lo[k] <= f.hi[k]) & (f.lo[k] <= e.hi[k]);
        if (overlap) add(e.index, f.index, pairs);
      }
    }
  }

  static bool onCandidate(fcl::CollisionObjectd* o1, fcl::CollisionObjectd* o2, void* data) {
    const Context& c = *static_cast<const Context*>(data);
    const int i = BoxProxy::indexOf(o1), j = BoxProxy::indexOf(o2);
    if (i != j && !bothFlagged(*c.flags, i, j) && touch<d>((*c.boxes)[i], (*c.boxes)[j])) add(i, j, *c.pairs);
    return false;  // keep going: we want every pair
  }

  // The tree over the bounded boxes, refitted or rebuilt; false if there is nothing in it.
  bool refreshTree(const std::vector<Box>& boxes) {
    while (proxies.size() < bounded.size()) proxies.push_back(std::make_unique<BoxProxy>(placeholder));
    for (std::size_t k = 0; k < bounded.size(); ++k) {
      const Box& b = boxes[bounded[k]];
      Eigen::Vector3d lo = Eigen::Vector3d::Constant(-kSlabHalfThickness), hi = Eigen::Vector3d::Constant(kSlabHalfThickness);
      lo.template head<d>() = b.min();
      hi.template head<d>() = b.max();
      proxies[k]->setBounds(lo, hi, bounded[k]);
    }
    if (bounded == registeredIndices && !registered.empty()) {
      manager.update();
    } else {
      manager.clear();
      registered.clear();
      for (std::size_t k = 0; k < bounded.size(); ++k) registered.push_back(proxies[k].get());
      registeredIndices = bounded;
      if (registered.empty()) return false;
      manager.registerObjects(registered);
      manager.setup();
    }
    return true;
  }

  // The tree's self-collision split into jobs that share no pair: a node's self-collision is its
  // children's and the two children against each other; two nodes against each other are the
  // larger one's children against the smaller (FCL's own rule), dropped when their boxes do not
  // overlap. Each job runs FCL's recursion into its own list; the lists are concatenated and
  // sorted afterwards, so the pairs are the same whatever runs where.
  using Node = fcl::DynamicAABBTreeCollisionManagerd::DynamicAABBNode;
  struct Job {
    Node* a;
    Node* b;  // null: a's self-collision
  };
  std::vector<Job> jobs, nextJobs;
  std::vector<std::vector<std::pair<int, int>>> jobPairs;
  static constexpr std::size_t kJobs = 32;     // about this many, so that two threads share them evenly
  static constexpr std::size_t kSplitFrom = 256;  // boxes; below, one FCL pass costs less than the handing over

  static bool useThreads(std::size_t boxes) {
    return boxes >= kSplitFrom && tbb::this_task_arena::max_concurrency() > 1;
  }

  void splitSelfCollision() {
    jobs.assign(1, Job{manager.getTree().getRoot(), nullptr});
    for (int depth = 0; depth < 8 && jobs.size() < kJobs; ++depth) {
      nextJobs.clear();
      for (const Job& j : jobs) {
        if (!j.b) {
          if (j.a->isLeaf()) continue;
          nextJobs.push_back({j.a->children[0], nullptr});
          nextJobs.push_back({j.a->children[1], nullptr});
          nextJobs.push_back({j.a->children[0], j.a->children[1]});
        } else if (!j.a->bv.overlap(j.b->bv)) {
          continue;
        } else if (j.a->isLeaf() && j.b->isLeaf()) {
          nextJobs.push_back(j);
        } else if (j.b->isLeaf() || (!j.a->isLeaf() && j.a->bv.size() > j.b->bv.size())) {
          nextJobs.push_back({j.a->children[0], j.b});
          nextJobs.push_back({j.a->children[1], j.b});
        } else {
          nextJobs.push_back({j.a, j.b->children[0]});
          nextJobs.push_back({j.a, j.b->children[1]});
        }
      }
      jobs.swap(nextJobs);
    }
  }

  // Runs job(k, context) for k in [0, count) on the arena's threads, each into its own list, and
  // appends the lists to `pairs` (in job order; the caller sorts).
  template <class Run>
  void runJobs(std::size_t count, const std::vector<Box>& boxes, const std::vector<char>& flags,
               std::vector<std::pair<int, int>>& pairs, Run&& run) {
    if (jobPairs.size() < count) jobPairs.resize(count);
    tbb::parallel_for(
        tbb::blocked_range<std::size_t>(0, count, 1),
        [&](const tbb::blocked_range<std::size_t>& r) {
          for (std::size_t k = r.begin(); k != r.end(); ++k) {
            jobPairs[k].clear();
            Context context{&boxes, &flags, &jobPairs[k]};
            run(k, context);
          }
        },
        tbb::simple_partitioner());
    for (std::size_t k = 0; k < count; ++k) pairs.insert(pairs.end(), jobPairs[k].begin(), jobPairs[k].end());
  }

  void dynamicTree(const std::vector<Box>& boxes, const std::vector<char>& flags, std::vector<std::pair<int, int>>& pairs) {
    if (!refreshTree(boxes)) return;
    if (!useThreads(bounded.size())) {
      Context context{&boxes, &flags, &pairs};
      manager.collide(&context, &Impl::onCandidate);
      return;
    }
    splitSelfCollision();
    runJobs(jobs.size(), boxes, flags, pairs, [&](std::size_t k, Context& context) {
      namespace tree = fcl::detail::dynamic_AABB_tree;
      if (jobs[k].b) tree::collisionRecurse<double>(jobs[k].a, jobs[k].b, &context, &Impl::onCandidate);
      else tree::selfCollisionRecurse<double>(jobs[k].a, &context, &Impl::onCandidate);
    });
  }

  // The bounded pairs with a box of `subset` in them: one tree query per such box (on the
  // arena's threads when there are many: each query only reads the tree).
  void dynamicTreeTouching(const std::vector<Box>& boxes, const std::vector<char>& flags,
                           const std::vector<char>& subset, std::vector<std::pair<int, int>>& pairs) {
    if (!refreshTree(boxes)) return;
    queried.clear();
    for (std::size_t k = 0; k < bounded.size(); ++k)
      if (subset[bounded[k]]) queried.push_back(static_cast<int>(k));
    if (!useThreads(queried.size() * 8)) {
      Context context{&boxes, &flags, &pairs};
      for (int k : queried) manager.collide(proxies[k].get(), &context, &Impl::onCandidate);
      return;
    }
    runJobs(queried.size(), boxes, flags, pairs, [&](std::size_t k, Context& context) {
      manager.collide(proxies[queried[k]].get(), &context, &Impl::onCandidate);
    });
  }
  std::vector<int> queried;  // dynamicTreeTouching: the proxies of the subset's boxes
};

template <int d>
BroadPhase<d>::BroadPhase(BroadPhaseMethod method) : method_(method), impl_(new Impl) {}

template <int d>
BroadPhase<d>::~BroadPhase() {
  delete impl_;
}

template <int d>
const std::vector<std::pair<int, int>>& BroadPhase<d>::findPairs(const std::vector<Eigen::AlignedBox<double, d>>& boxes,
                                                                 const std::vector<char>& isInfinite) {
  return collect(boxes, isInfinite, nullptr);
}

template <int d>
const std::vector<std::pair<int, int>>& BroadPhase<d>::findPairsTouching(
    const std::vector<Eigen::AlignedBox<double, d>>& boxes, const std::vector<char>& isInfinite,
    const std::vector<char>& subset) {
  if (subset.size() != boxes.size())
    throw std::invalid_argument("broad phase: subset has " + std::to_string(subset.size()) + " flags for " +
                                std::to_string(boxes.size()) + " boxes");
  if (method_ == BroadPhaseMethod::FclDynamicTree) return collect(boxes, isInfinite, &subset);
  // Below the size where the tree pays, a full sweep, filtered.
  collect(boxes, isInfinite, nullptr);
  pairs_.erase(std::remove_if(pairs_.begin(), pairs_.end(),
                              [&](const std::pair<int, int>& p) { return !subset[p.first] && !subset[p.second]; }),
               pairs_.end());
  return pairs_;
}

template <int d>
const std::vector<std::pair<int, int>>& BroadPhase<d>::collect(const std::vector<Eigen::AlignedBox<double, d>>& boxes,
                                                               const std::vector<char>& isInfinite,
                                                               const std::vector<char>* subset) {
  const int n = static_cast<int>(boxes.size());
  if (!isInfinite.empty() && static_cast<int>(isInfinite.size()) != n)
    throw std::invalid_argument("broad phase: isInfinite has " + std::to_string(isInfinite.size()) + " flags for " +
                                std::to_string(n) + " boxes");
  Impl& impl = *impl_;
  impl.bounded.clear();
  impl.unbounded.clear();
  for (int i = 0; i < n; ++i) {
    if (boxes[i].min().hasNaN() || boxes[i].max().hasNaN())
      throw std::invalid_argument("broad phase: box " + std::to_string(i) + " has a NaN bound");
    (isUnbounded<d>(boxes[i]) ? impl.unbounded : impl.bounded).push_back(i);
  }
  pairs_.clear();
  // Every box of infinite mass (a pile asleep on the ground): no pair can be reported.
  if (!isInfinite.empty() && std::find(isInfinite.begin(), isInfinite.end(), 0) == isInfinite.end()) return pairs_;
  if (subset) impl.dynamicTreeTouching(boxes, isInfinite, *subset, pairs_);
  else if (method_ == BroadPhaseMethod::SweepAndPrune) impl.sweepAndPrune(boxes, isInfinite, pairs_);
  else impl.dynamicTree(boxes, isInfinite, pairs_);
  for (int u : impl.unbounded)
    for (int j = 0; j < n; ++j) {
      if (j == u || (j < u && isUnbounded<d>(boxes[j]))) continue;  // each unbounded pair once
      if (subset && !(*subset)[u] && !(*subset)[j]) continue;
      if (!Impl::bothFlagged(isInfinite, u, j) && touch<d>(boxes[u], boxes[j])) Impl::add(u, j, pairs_);
    }
  impl.sortPairs(pairs_, n);
  pairs_.erase(std::unique(pairs_.begin(), pairs_.end()), pairs_.end());
  if (!excluded_.empty())
    pairs_.erase(std::remove_if(pairs_.begin(), pairs_.end(),
                                [&](const std::pair<int, int>& p) {
                                  return std::binary_search(excluded_.begin(), excluded_.end(), p);
                                }),
                 pairs_.end());
  return pairs_;
}

template class BroadPhase<2>;
template class BroadPhase<3>;

}  // namespace monolith::solvers::collision
