#pragma once
// Velocities for the faces a one-phase flow leaves without one (air faces), so that advection can
// read across the free surface: each unknown face takes the mean of its known same-axis
// neighbours, layer by layer. Shared by the coupled one-phase solve (two_phase_flow.cpp) and the
// pressure jump comparison scheme (pressure_jump.cpp).
#include <Eigen/Core>
#include <vector>

#include "solvers/mac_layout.h"

namespace monolith::solvers {

// known[f] != 0 marks the faces whose velocity stands. The others are set to 0 and then filled,
// for `layers` layers, by averaging their known neighbours one face away along either axis (a face
// filled in a layer counts as known from the next layer on). Faces no layer reaches stay 0.
void extrapolateToUnknownFaces(const MacLayout<2>& layout, std::vector<char> known, Eigen::VectorXd& u, int layers = 4);

}  // namespace monolith::solvers
