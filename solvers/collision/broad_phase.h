#pragma once
// Broad phase: candidate pairs of overlapping world bounding boxes.
#include <utility>
#include <vector>

#include <Eigen/Geometry>

namespace monolith::solvers::collision {

enum class BroadPhaseMethod { SweepAndPrune, FclDynamicTree };

// Returns every pair (i, j), i < j, whose boxes overlap (closed boxes: touching counts), sorted
// lexicographically, so the result is independent of the method and of thread count.
// `isInfinite` (empty, or one flag per box) filters pairs: two flagged boxes (half-spaces, or
// static bodies that never collide with each other) are never paired. Boxes reaching beyond
// 1e20 (a half-space's box) are checked against every box directly, whatever their flag.
// Throws std::invalid_argument for a flag count that does not match or a NaN bound.
template <int d>
class BroadPhase {
 public:
  explicit BroadPhase(BroadPhaseMethod method = BroadPhaseMethod::SweepAndPrune);
  ~BroadPhase();
  BroadPhase(const BroadPhase&) = delete;
  BroadPhase& operator=(const BroadPhase&) = delete;

  // Reuses internal storage across calls (no allocation per step once warmed up).
  const std::vector<std::pair<int, int>>& findPairs(const std::vector<Eigen::AlignedBox<double, d>>& boxes,
                                                    const std::vector<char>& isInfinite);
  // The pairs of findPairs that involve at least one box flagged in `subset` (one flag per box),
  // sorted the same way: after a few boxes grew, their new pairs without a full pass (the tree
  // is queried with those boxes only).
  const std::vector<std::pair<int, int>>& findPairsTouching(const std::vector<Eigen::AlignedBox<double, d>>& boxes,
                                                            const std::vector<char>& isInfinite,
                                                            const std::vector<char>& subset);
  BroadPhaseMethod method() const { return method_; }
  // Pairs never reported (sorted, first < second): bodies joined by an articulation joint,
  // which are shaped not to touch where they meet but may swing into each other.
  void excludePairs(const std::vector<std::pair<int, int>>& sortedPairs) { excluded_ = sortedPairs; }

 private:
  // Both queries: the pairs of all boxes, or (tree only) those with a box of `subset`.
  const std::vector<std::pair<int, int>>& collect(const std::vector<Eigen::AlignedBox<double, d>>& boxes,
                                                  const std::vector<char>& isInfinite, const std::vector<char>* subset);
  BroadPhaseMethod method_;
  struct Impl;
  Impl* impl_;
  std::vector<std::pair<int, int>> pairs_;
  std::vector<std::pair<int, int>> excluded_;
};

}  // namespace monolith::solvers::collision
