#pragma once
// Deterministic data-parallel loop over [0, n) for the deformable solvers: the split into blocks
// of `grain` does not depend on the thread count (simple partitioner) and every index is written
// by one task, so results are bitwise the same on any number of threads.
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/partitioner.h>

namespace monolith::solvers::deformable {

template <class F>
void parallelIndices(int n, F&& f, int grain = 16) {
  if (n <= 0) return;
  tbb::parallel_for(
      tbb::blocked_range<int>(0, n, grain),
      [&](const tbb::blocked_range<int>& r) {
        for (int i = r.begin(); i != r.end(); ++i) f(i);
      },
      tbb::simple_partitioner());
}

}  // namespace monolith::solvers::deformable
