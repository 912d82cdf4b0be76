#pragma once
// The explicit-elasticity time-step limit of a deformable body (thesis Sec. 4.3, 5.4: "we are
// still explicit on elastic forces, and this continues to impose a CFL restriction"). The frame
// is split into substeps no longer than cfl times this step, and every substep runs all five
// Newmark steps for rigid and deformable bodies together (Table 4.1's "substeps per frame").
//
// Finite elements: the dilatational wave speed c = sqrt((lambda + 2 mu) / rho) crosses the
// smallest element altitude h in h / c; for a chain of linear elements with lumped masses this
// is exactly the velocity-Verlet limit 2 / omega_max. The altitude is the current one (a
// compressed element is thinner and stiffer), floored at `clamp` times the rest altitude: an
// element crushed beyond that answers with bounded forces (the inversion-robust stress keeps
// its singular values clamped), and a zero step would stall the run.
// Springs: omega_max^2 <= max_i 2 K_i / m_i (Gershgorin on M^-1 K, K_i the summed stiffness of
// the springs at particle i), so the limit is sqrt(2 m_i / K_i).
// Both are also limited by the motion: no free particle moves more than the smallest element
// altitude per step at CFL 1, so collision candidates stay local.
#include <vector>

#include "solvers/deformable/elasticity.h"

namespace monolith::solvers::deformable {

struct StableStep {
  double elastic = 0;   // the elastic limit (infinite without stiffness)
  double motion = 0;    // smallest altitude / fastest free particle speed (infinite at rest)
  double minAltitude = 0;
  double value() const { return elastic < motion ? elastic : motion; }
};

// fixed: per particle, nonzero for particles that do not move freely (not counted in the motion
// limit, nor in the spring limit).
template <int d>
StableStep stableStep(const ForceModel<d>& fm, double density, const double* x, const double* v,
                      const std::vector<int>& fixed);

}  // namespace monolith::solvers::deformable
