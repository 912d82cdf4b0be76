#pragma once
// Ghost rules for the advection's samples next to obstacle walls that sit at the obstacle's true
// surface or at the staircase's cell boundary (FluidDomain::wallDistance, scenes with
// "obstacle_wall": "surface" or "cell_boundary"). The viscous
// operator already places the no-slip wall there (operators.h); these rules make the advection
// see the same wall (velocity_sampling.h, rule 3b), instead of a zero-gradient extension into the
// obstacle (rule 4) or the wall velocity at the obstacle face's centre.
//
// For each free face g of axis a and each direction ±e_b with b != a whose neighbour face h is a
// prescribed obstacle face, the wall lies theta cells from g towards h (theta in (0, 1]). The
// ghost value of h continues the velocity linearly through the wall:
//   * theta >= 1/2: from g, factor -(1 - theta) / theta, in [-1, 0];
//   * theta <  1/2: from the free face o one cell beyond g (1 + theta cells from the wall), factor
//     -(1 - theta) / (1 + theta), in (-1, -1/3]: extending from g would need a factor below -1,
//     which would make a sample leave the range of the fluid values. If o is not free, from g with
//     the factor clamped to -1 (the wall then sits half way, not at theta).
// Each rule is exact for a velocity that is linear along b and equals the wall's velocity at the
// wall. Pairs along the face's own axis (b == a) are left out: there h carries the normal
// velocity, which no-penetration fixes at h itself (thesis Sec. 5.4.1). For the same reason a
// prescribed h with a fluid cell on one side (a face on the side of the staircase, at a corner of
// the obstacle as seen from g) gets no ghost value either: its own velocity holds exactly where it
// sits, and a ghost value there would also be read by samples along h's axis, between h and the
// fluid, where it would misstate no-penetration. Only faces inside the obstacle get ghosts.
// (DFG 2D-2 on the staircase with the cell-boundary wall, 440 x 82: c_L,max -12.2 % -> -9.0 %,
// c_D,max +9.7 % -> +7.2 %; docs/benchmarks.md.)
// Without wall distances (the thesis's staircase, wall at the obstacle face's centre) no rules.
#include "solvers/advection/velocity_sampling.h"
#include "solvers/fluid/boundary.h"

#include <vector>

namespace monolith::solvers {

template <int d>
std::vector<GhostRule> obstacleWallGhosts(const FluidDomain<d>& domain);

}  // namespace monolith::solvers
