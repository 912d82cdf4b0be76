#pragma once
// Deterministic data-parallel loop over [0, n): every index is written by exactly one task and
// the split does not depend on the thread count (fixed grain, simple partitioner), so results
// are bitwise identical for any number of threads (STYLE.md practice 5).
#include <cstddef>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/partitioner.h>

namespace monolith {

inline constexpr std::size_t kBodyGrain = 64;

template <class F>
void parallelForEachIndex(std::size_t n, F&& f, std::size_t grain = kBodyGrain) {
  if (n == 0) return;
  tbb::parallel_for(
      tbb::blocked_range<std::size_t>(0, n, grain),
      [&](const tbb::blocked_range<std::size_t>& r) {
        for (std::size_t i = r.begin(); i != r.end(); ++i) f(i);
      },
      tbb::simple_partitioner());
}

}  // namespace monolith
