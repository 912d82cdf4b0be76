#include "solvers/surface_tension/pressure_jump.h"

#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>
#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <utility>

#include "solvers/advection/semi_lagrangian.h"
#include "solvers/surface_tension/face_extrapolation.h"
#include "solvers/surface_tension/front.h"
#include "solvers/surface_tension/level_set_front.h"
#include "solvers/surface_tension/level_set_tracking.h"

namespace monolith::solvers {

using Index2 = Eigen::Vector2i;

std::vector<double> levelSetCurvature(const MacLayout<2>& layout, const std::vector<double>& phi) {
  const int nx = layout.cells.x(), ny = layout.cells.y();
  const double h = layout.dx;
  auto at = [&](int i, int j) {
    return phi[static_cast<std::size_t>(std::clamp(j, 0, ny - 1)) * nx + std::clamp(i, 0, nx - 1)];
  };
  std::vector<double> kappa(phi.size(), 0.0);
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      const double px = (at(i + 1, j) - at(i - 1, j)) / (2 * h), py = (at(i, j + 1) - at(i, j - 1)) / (2 * h);
      const double pxx = (at(i + 1, j) - 2 * at(i, j) + at(i - 1, j)) / (h * h);
      const double pyy = (at(i, j + 1) - 2 * at(i, j) + at(i, j - 1)) / (h * h);
      const double pxy = (at(i + 1, j + 1) - at(i + 1, j - 1) - at(i - 1, j + 1) + at(i - 1, j - 1)) / (4 * h * h);
      const double g2 = px * px + py * py;
      double k = g2 > 0 ? (pxx * py * py - 2 * px * py * pxy + pyy * px * px) / std::pow(g2, 1.5) : 0.0;
      kappa[static_cast<std::size_t>(j) * nx + i] = std::clamp(k, -1 / h, 1 / h);
    }
  return kappa;
}

namespace {
// Air faces (no fluid cell on either side) get velocities from their fluid neighbours; walls stay 0.
void extrapolateVelocity(const MacLayout<2>& layout, const std::vector<char>& fluid, Eigen::VectorXd& u) {
  std::vector<char> known(layout.totalFaces(), 0);
  for (int f = 0; f < layout.totalFaces(); ++f) {
    const auto [axis, idx] = layout.faceCoord(f);
    if (idx[axis] == 0 || idx[axis] == layout.cells[axis]) {
      known[f] = 1;
      continue;
    }
    Index2 lower = idx;
    lower[axis] -= 1;
    known[f] = fluid[layout.cellIndex(idx)] || fluid[layout.cellIndex(lower)];
  }
  extrapolateToUnknownFaces(layout, std::move(known), u);
}
}  // namespace

PressureJumpReport advancePressureJump(PressureJumpState& state, const PressureJumpSettings& settings, double dt) {
  if (!(dt > 0) || !std::isfinite(dt)) throw std::invalid_argument("advancePressureJump: dt must be positive and finite");
  const MacLayout<2>& layout = state.layout;
  const int nc = layout.cellCount(), nf = layout.totalFaces();
  const double h = layout.dx, rho = settings.density;
  if (static_cast<int>(state.phi.size()) != nc) throw std::invalid_argument("advancePressureJump: phi needs one value per cell");
  PressureJumpReport report;
  std::vector<char> fluid(nc);
  for (int c = 0; c < nc; ++c) fluid[c] = state.phi[c] < 0;

  // u*: extrapolation into the air, then advection.
  Eigen::VectorXd u = state.u;
  extrapolateVelocity(layout, fluid, u);
  u = advectFacesSemiLagrangian(layout, u, dt);

  // The Poisson equation -L p = -(rho / dt) div u* + Dirichlet terms on the fluid cells.
  const std::vector<double> kappa = levelSetCurvature(layout, state.phi);
  std::vector<int> dof(nc, -1);
  int count = 0;
  for (int c = 0; c < nc; ++c)
    if (fluid[c]) dof[c] = count++;
  std::vector<Eigen::Triplet<double>> triplets;
  Eigen::VectorXd rhs = Eigen::VectorXd::Zero(count);
  // Per interior face between a fluid and an air cell: theta and the interface pressure.
  std::vector<double> theta(nf, 0.0), interfacePressure(nf, 0.0);
  for (int f = 0; f < nf; ++f) {
    const auto [axis, idx] = layout.faceCoord(f);
    if (idx[axis] == 0 || idx[axis] == layout.cells[axis]) continue;  // walls: Neumann, u = 0
    Index2 lower = idx;
    lower[axis] -= 1;
    const int a = layout.cellIndex(lower), b = layout.cellIndex(idx);
    if (!fluid[a] && !fluid[b]) continue;
    // Divergence of u*: the face carries flow out of a and into b.
    if (fluid[a]) rhs[dof[a]] -= rho / dt * u[f] / h;
    if (fluid[b]) rhs[dof[b]] += rho / dt * u[f] / h;
    if (fluid[a] && fluid[b]) {
      triplets.emplace_back(dof[a], dof[a], 1 / (h * h));
      triplets.emplace_back(dof[b], dof[b], 1 / (h * h));
      triplets.emplace_back(dof[a], dof[b], -1 / (h * h));
      triplets.emplace_back(dof[b], dof[a], -1 / (h * h));
      continue;
    }
    const int in = fluid[a] ? a : b, out = fluid[a] ? b : a;
    const double t = std::max(1e-3, state.phi[in] / (state.phi[in] - state.phi[out]));
    theta[f] = t;
    interfacePressure[f] = settings.sigma * (kappa[in] + t * (kappa[out] - kappa[in]));
    triplets.emplace_back(dof[in], dof[in], 1 / (t * h * h));
    rhs[dof[in]] += interfacePressure[f] / (t * h * h);
  }
  Eigen::SparseMatrix<double> A(count, count);
  A.setFromTriplets(triplets.begin(), triplets.end());
  Eigen::VectorXd p = Eigen::VectorXd::Zero(count);
  if (count > 0) {
    Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> solver(A);
    if (solver.info() != Eigen::Success) throw std::runtime_error("advancePressureJump: the Poisson matrix did not factor");
    p = solver.solve(rhs);
  }
  // The projection.
  double maxSpeed = 0;
  bool finite = true;
  for (int f = 0; f < nf; ++f) {
    const auto [axis, idx] = layout.faceCoord(f);
    if (idx[axis] == 0 || idx[axis] == layout.cells[axis]) {
      u[f] = 0;
      continue;
    }
    Index2 lower = idx;
    lower[axis] -= 1;
    const int a = layout.cellIndex(lower), b = layout.cellIndex(idx);
    if (!fluid[a] && !fluid[b]) continue;
    double gradient;
    if (fluid[a] && fluid[b]) gradient = (p[dof[b]] - p[dof[a]]) / h;
    else if (fluid[a]) gradient = (interfacePressure[f] - p[dof[a]]) / (theta[f] * h);
    else gradient = (p[dof[b]] - interfacePressure[f]) / (theta[f] * h);
    u[f] -= dt / rho * gradient;
    if (!std::isfinite(u[f])) finite = false;
    maxSpeed = std::max(maxSpeed, std::abs(u[f]));
  }
  extrapolateVelocity(layout, fluid, u);
  state.u = u;

  // The level set moves with the new velocity; its mesh gives the area, and phi is redistanced.
  state.phi = advectCellField(layout, state.phi, state.u, dt);
  state.time += dt;
  ++state.step;
  report.maxSpeed = maxSpeed;
  std::ostringstream why;
  why << "pressure jump surface tension blew up at step " << state.step << " (t = " << state.time << "): ";
  if (!finite || maxSpeed > settings.blowUpSpeed) {
    report.blewUp = true;
    why << "max speed " << maxSpeed << " above the guard " << settings.blowUpSpeed;
    report.blowUpReason = why.str();
    return report;
  }
  try {
    const Front2 mesh = frontFromLevelSet(layout, state.phi, CrossingOrder::Fourth);
    report.area = enclosedArea(mesh);
    redistanceToFront(layout, mesh, state.phi, 5, settings.keep);
  } catch (const std::invalid_argument&) {
    report.blewUp = true;
    why << "the level set's mesh no longer forms closed curves";
    report.blowUpReason = why.str();
  }
  return report;
}

}  // namespace monolith::solvers
