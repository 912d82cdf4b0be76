#pragma once
// Semi-Lagrangian self-advection of MAC face velocities, the convective step of thesis Sec. 5.2
// (eq. 5.3, "semi-Lagrangian advection scheme (see e.g. [129])", advected with the time-n
// velocities). Each face is traced backwards through the frozen field u^n with the 2nd-order
// midpoint (RK2) rule
//     x_mid = x_f - dt/2 u(x_f),   x_dep = x_f - dt u(x_mid),   u_f^{n+1} = u_a(x_dep),
// and the sample is taken with FaceVelocitySampler (see velocity_sampling.h for the boundary,
// clipping and solid rules; both traced points are clipped to the fluid region). Prescribed
// faces are not traced: they receive their prescribed velocity.
//
// Accuracy: the trace is O(dt^3) per step, multilinear interpolation O(dx^2) per step, so the
// global error after T/dt steps is O(dt^2 + dx^2/dt), i.e. first order at fixed CFL
// (measured in tests/unit/test_advection.cpp). Unconditionally stable: each value is a convex
// combination of old values.
//
// Parallel over faces with tbb::parallel_for; every output face is written exactly once from
// read-only input, so the result is bitwise independent of the thread count.
#include "solvers/advection/velocity_sampling.h"
#include "solvers/mac_layout.h"

#include <Eigen/Core>

namespace monolith::solvers {

// u has one value per face (layout.faceIndex order); dt >= 0 and finite. Throws
// std::invalid_argument on bad sizes / boundary / dt.
template <int d>
Eigen::VectorXd advectFacesSemiLagrangian(const MacLayout<d>& layout, const Eigen::VectorXd& u, double dt,
                                          const FaceBoundary& boundary = {});

// Limited MacCormack / back-and-forth correction of the semi-Lagrangian step (Selle, Fedkiw,
// Kim, Liu & Rossignac 2008; not in the thesis, an option next to its two schemes). With
// A(q) the step above, q^ = A(u) and the round trip q~ = A^R(q^) (the same characteristics
// traced forwards through u^n):
//     u^{n+1} = clamp(q^ + (u^n - q~)/2, range of the face values A blended at the departure point).
// Second order in dx and dt where the clamp is inactive, for two semi-Lagrangian passes; the
// clamp keeps every value within the old values around its departure point, so it is as stable
// as the plain step. Its smaller numerical diffusion is what lets a 256^2 lid-driven cavity at
// Re 1000 reach Ghia's profiles (docs/benchmarks.md). Same arguments and errors as above.
template <int d>
Eigen::VectorXd advectFacesMacCormack(const MacLayout<d>& layout, const Eigen::VectorXd& u, double dt,
                                      const FaceBoundary& boundary = {});

}  // namespace monolith::solvers
