#pragma once
// How the last solve of a pair's manifold ended (manifold_problem.h), in its own header so that
// the contact workspace can keep one per pair without the solvers' headers.
#include <cstdint>

namespace monolith::solvers::contact {

// Per point in the narrow phase's order: the exact finish starts the pair's next solve from it
// (one pass instead of one per point that turns to sliding). ContactPairState keeps one per
// pair, within the step.
struct ManifoldSolveEnd {
  static constexpr int kPoints = 8;
  std::uint16_t states = 0;    // 2 bits of PointState (manifold_polish.h) per point
  signed char points = 0;      // 0: nothing remembered
  float angles[kPoints] = {};  // a sliding point's friction direction in its tangent basis
};

}  // namespace monolith::solvers::contact
