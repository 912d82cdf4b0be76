#pragma once
// Level-set-tracked fronts (thesis Sec. 6.3.1, "Level Set Tracked"): the cell-centred level set is
// advected with the grid velocity, the surface mesh is rebuilt from it every step (level_set_front.h,
// fourth-order crossings, slivers < 0.1 dx merged), and the level set is made a distance again
// beyond `keep` cells: here the exact distance to that mesh between `keep` and `band` cells from it
// (values beyond the band are clamped to +-band dx; only the signs are read there); fast marching
// (fast_marching.h) is the other choice, and the particle level set [47] (particle_level_set.h)
// corrects phi around it. The values within `keep` cells, which the crossing stencils read, stay the
// advected ones: the distance to the mesh's chords moves the interface inward by O(dx^2 / r) each
// step (measured: 8 % of a 20-cell drop's area in 20 steps with keep = 0), and with keep = 2 it still
// changed values the stencils read, enough to stop the parasitic currents converging.
#include <vector>

#include "solvers/mac_layout.h"
#include "solvers/surface_tension/front.h"

namespace monolith::solvers {

// Bilinear sample of a cell-centred field at x (clamped to the cell centres' box).
double sampleCellField(const MacLayout<2>& layout, const std::vector<double>& phi, const Eigen::Vector2d& x);

// Semi-Lagrangian (midpoint rule) advection of a cell-centred field through the face velocities u.
std::vector<double> advectCellField(const MacLayout<2>& layout, const std::vector<double>& phi, const Eigen::VectorXd& u,
                                    double dt);

// The implicit level-set update (beyond the thesis; its Sec. 6.5 future work): every cell within
// `band` dx of the front takes the normal speed of its closest point on the front, the point
// velocities `velocity` (one per front point, e.g. H u^{n+1}) interpolated linearly along the segment
// and projected on its outward normal V, and phi -= dt V (phi is a signed distance, |grad phi| = 1).
// The zero level set then moves as the front's points do, to first order, without the inward drift of
// redistancing to the chords.
void moveLevelSetWithFront(const MacLayout<2>& layout, const Front2& front, const std::vector<Eigen::Vector2d>& velocity,
                           double dt, std::vector<double>& phi, double band = 5);

// Signed distance to `front` (negative inside, sign taken from `phi`) for the cells between `keep`
// and `band` cells from it.
void redistanceToFront(const MacLayout<2>& layout, const Front2& front, std::vector<double>& phi, double band = 5,
                       double keep = 3);

// Exact signed distance to a closed front (negative inside), clamped to +-band dx.
std::vector<double> signedDistanceToFront(const MacLayout<2>& layout, const Front2& front, double band = 4);

}  // namespace monolith::solvers
