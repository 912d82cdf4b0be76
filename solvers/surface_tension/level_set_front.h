#pragma once
// The surface mesh of a level-set-tracked front (thesis Sec. 6.3.1, "Level Set Tracked"): a
// marching-squares mesh on the fluid grid's cells whose points are the level set's crossings of
// the grid lines, located to third or fourth order from the cell-centred level set:
//  * node values (cell corners): the fourth-order stencil -1/32 (8 outer) + 5/16 (4 inner);
//  * face values: -1/16 (phi_{j-1} + phi_{j+2}) + 9/16 (phi_j + phi_{j+1});
//  * third order: the quadratic through (0, node), (1/2, face), (1, node);
//    fourth order: the cubic through (-1/2, face below), (0, node), (1, node), (3/2, face above);
//    its root in [0, 1] (bracketed by the node signs) by a bracketed secant method.
// Segments shorter than 0.1 dx are merged into a neighbour (slivers spoil the curvature, Sec. 6.3.2).
// phi < 0 is the inside phase; segments are oriented with the inside on their left.
#include <Eigen/Core>
#include <vector>

#include "solvers/mac_layout.h"
#include "solvers/surface_tension/front.h"

namespace monolith::solvers {

enum class CrossingOrder { Third = 3, Fourth = 4 };

// phi: one value per cell of `layout` (x fastest). Stencils reaching outside the grid clamp to the
// nearest cell. Points closer than 0.1 dx are merged (sliverLength = 0 keeps every segment).
// nodeSnap > 0: the crossings on the edges of a node whose value lies within nodeSnap dx of zero are
// put on the node (one shared point). That moves them by at most about nodeSnap dx normal to the
// front, so Table 6.1 is measured without it; the two-phase flow uses it (TwoPhaseSettings::
// levelSetNodeSnap) because a front passing a node at a roundoff-to-tiny distance makes crossings
// that flip between the node's edges from step to step (docs/benchmarks_surface_tension.md).
Front2 frontFromLevelSet(const MacLayout<2>& layout, const std::vector<double>& phi, CrossingOrder order,
                         double sliverFraction = 0.1, double nodeSnap = 0);

// Removes every segment shorter than minLength by deleting one of its endpoints (an interior point of
// its polyline; the one whose removal leaves the shorter merged segment, unless that merged segment
// would lie on a grid line: a cap over a line, tip deleted, whose faces could not be told inside from
// outside). Returns the count removed.
int mergeSlivers(Front2& front, double minLength);

// Root in [0, 1] of the polynomial through the samples (t_i, v_i) (3 or 4 of them), with v(0) and
// v(1) of opposite signs (or one zero): bracketed secant (regula falsi with the Illinois fix).
double crossingParameter(const std::vector<double>& t, const std::vector<double>& v);

}  // namespace monolith::solvers
