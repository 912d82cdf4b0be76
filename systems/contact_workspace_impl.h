#pragma once
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/partitioner.h>

#include <algorithm>
#include <utility>
#include <vector>

namespace monolith {

template <int d>
template <typename PosesOf>
int ContactWorkspace<d>::growPairs(PosesOf&& poses) {
  const std::size_t n = bodies.size();
  std::vector<char>& grew = grew_;  // kept across calls: no allocation per step
  grew.assign(n, 0);
  const VecD pad = VecD::Constant(settings.thickness);
  // Each body's box in its own slot: a plain parallel loop.
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 256), [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t i = r.begin(); i != r.end(); ++i) {
      const ContactBody<d>& b = bodies[i];
      if (b.isStatic) continue;
      for (const auto& pose : poses(b)) {
        Eigen::AlignedBox<double, d> box = solvers::collision::worldBounds(*b.geometry, pose);
        box.min() -= pad;
        box.max() += pad;
        // Growth up to push-out's tolerance is ignored (the box is left as it is): a pair it
        // could add overlaps by less than twice that (both bodies may have crept out), within
        // what push-out leaves alone.
        const Eigen::AlignedBox<double, d>& known = boxes_[i];
        const double beyond = std::max((known.min() - box.min()).maxCoeff(), (box.max() - known.max()).maxCoeff());
        if (!(beyond > settings.pushOutTolerance)) continue;
        boxes_[i].extend(box);
        grew[i] = 1;
      }
    }
  });
  const std::size_t grown = static_cast<std::size_t>(std::count(grew.begin(), grew.end(), char(1)));
  if (grown == 0) return 0;
  if (grown * 8 >= n) {
    // Many grew: one full pass (a tree query per box costs about what a whole pass costs per
    // eight boxes, measured on the 4000-sphere pour). It finds every known pair again.
    const auto& found = broadPhase_->findPairs(boxes_, infinite_);
    const int added = static_cast<int>(found.size()) - static_cast<int>(pairs.size());
    if (added > 0) rebuildPairsFrom(found);
    return added;
  }
  // Few grew: only pairs with a grown box can be new, merged with the known ones (both sorted).
  const auto& touching = broadPhase_->findPairsTouching(boxes_, infinite_, grew);
  std::vector<std::pair<int, int>>& all = mergedPairs_;
  all.clear();
  std::size_t k = 0;
  for (const auto& t : touching) {
    while (k < pairs.size() && std::make_pair(pairs[k].a, pairs[k].b) < t) {
      all.emplace_back(pairs[k].a, pairs[k].b);
      ++k;
    }
    if (k < pairs.size() && std::make_pair(pairs[k].a, pairs[k].b) == t) ++k;
    all.push_back(t);
  }
  for (; k < pairs.size(); ++k) all.emplace_back(pairs[k].a, pairs[k].b);
  const int added = static_cast<int>(all.size()) - static_cast<int>(pairs.size());
  if (added > 0) rebuildPairsFrom(all);
  return added;
}

}  // namespace monolith
