#pragma once
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/partitioner.h>

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

}  // namespace monolith
