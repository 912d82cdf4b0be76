#pragma once
// Advective time-step restriction. The thesis chooses the fluid step with a CFL number of 0.9
// (Sec. 5.11, "The fluid time step size is computed using a CFL number of 0.9 for all of our
// examples") and takes the minimum with the structure's step; the scene sets the number.
//     dt = cfl * dx / max_f |u_f|     (max over all stored faces, prescribed ones included)
// This uses the largest single face component; the summed multi-dimensional Courant number
// dt * sum_a |u_a| / dx can then reach d * cfl (see eno.h for the ENO/RK3 stability range).
#include "solvers/advection/velocity_sampling.h"
#include "solvers/mac_layout.h"

#include <Eigen/Core>

namespace monolith::solvers {

inline constexpr double kThesisCflNumber = 0.9;  // thesis Sec. 5.11

// max |u_f| over all faces, prescribed faces read as their prescribed velocity. Throws
// std::invalid_argument if the sizes disagree and std::domain_error on a non-finite velocity.
double maxFaceSpeed(const Eigen::VectorXd& u, const FaceBoundary& boundary = {});

// min(cfl * dx / maxFaceSpeed, dtMax); returns dtMax when the field is at rest (the u = 0
// guard: no advective restriction). Throws std::invalid_argument unless cfl > 0 and dtMax > 0
// (dtMax may be +infinity; then a resting field returns +infinity).
template <int d>
double cflTimeStep(const MacLayout<d>& layout, const Eigen::VectorXd& u, double cfl, double dtMax,
                   const FaceBoundary& boundary = {});

}  // namespace monolith::solvers
