#pragma once
// Fast-marching redistancing of a cell-centred level set (Sethian 1996; the reinitialisation the
// thesis's level-set-tracked fronts use, Sec. 6.3.1, and the one of the particle level set [47]).
//
// The cells next to the interface (a face neighbour of the other sign) start from the distance
// that linear interpolation of phi along each axis gives: theta_a dx with theta = phi_c / (phi_c -
// phi_n) per axis a (the nearer crossing), combined as 1 / sqrt(sum 1 / d_a^2), the distance to the
// line through the crossings. All other cells are marched outward in order of distance with the
// first-order upwind update of |grad phi| = 1:
//   (d - a)^2 + (d - b)^2 = dx^2, with a, b the smaller accepted neighbour per axis
//   (d = min(a, b) + dx when |a - b| >= dx).
// Both sides march at once (on |phi|), the sign is kept. The error is O(dx^2) in the start cells and
// O(dx) beyond (first order).
//
// keep > 0: the cells with |phi| <= keep dx (and some neighbour in the band) are taken as they are,
// not re-initialised, and only the cells beyond are marched from them. This keeps the values that the
// front's crossing stencils read (level_set_front.h) while the rest is made a distance again.
// Cells farther than band dx are clamped to +-band dx. Deterministic (ties broken by cell index).
#include <vector>

#include "solvers/mac_layout.h"

namespace monolith::solvers {

void fastMarchingRedistance(const MacLayout<2>& layout, std::vector<double>& phi, double band = 6, double keep = 0);

}  // namespace monolith::solvers
