#pragma once
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/partitioner.h>

#include <algorithm>

namespace monolith {

template <int d>
template <class F>
void ContactWorkspace<d>::forEachIsland(F&& f) {
  const std::size_t n = islands.members.size();
  if (n == 0) return;
  tbb::parallel_for(
      tbb::blocked_range<std::size_t>(0, n, 1),
      [&](const tbb::blocked_range<std::size_t>& r) {
        for (std::size_t i = r.begin(); i != r.end(); ++i) f(static_cast<int>(i));
      },
      tbb::simple_partitioner());
}

template <int d>
template <typename PosesOf>
int ContactWorkspace<d>::growPairs(PosesOf&& poses) {
  const std::size_t n = bodies.size();
  std::vector<char> grew(n, 0);
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
        if (boxes_[i].contains(box)) continue;
        boxes_[i].extend(box);
        grew[i] = 1;
      }
    }
  });
  if (std::find(grew.begin(), grew.end(), char(1)) == grew.end()) return 0;
  const auto& found = broadPhase_->findPairs(boxes_, infinite_);
  const int added = static_cast<int>(found.size()) - static_cast<int>(pairs.size());
  if (added > 0) rebuildPairsFrom(found);
  return added;
}

}  // namespace monolith
