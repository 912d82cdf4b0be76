#include "systems/fluid_projection.h"

#include <algorithm>
#include <cmath>

#include "solvers/fluid/projection.h"
#include "systems/fluid_domain.h"
#include "systems/fluid_preconditioner_kind.h"

namespace monolith {

template <int d>
struct FluidProjection<d>::Cache {
  std::vector<std::uint8_t> solid;  // geometry the operators were built for
  std::vector<ObstacleMotion<d>> motions;  // moving obstacles' velocities sit in the operators' RHS terms
  std::vector<double> wallDistance;        // obstacle surfaces seen by the viscous rows
  std::vector<double> wallVelocity;        // and their velocities
  std::vector<double> openFraction;        // cut faces
  double dt = -1, density = 0, viscosity = -1;
  solvers::PoissonPreconditionerKind kind = solvers::PoissonPreconditionerKind::None;
  std::unique_ptr<solvers::FluidOperators<d>> ops;
  bool cutCorrection = false;
  std::unique_ptr<solvers::PoissonPreconditioner<d>> preconditioner;
  std::unique_ptr<solvers::CoupledPreconditioner<d>> coupled;  // wraps `preconditioner`
};

template <int d>
FluidProjection<d>::FluidProjection() : cache_(std::make_unique<Cache>()) {}
template <int d>
FluidProjection<d>::~FluidProjection() = default;

template <int d>
void FluidProjection<d>::run(World<d>& world, StepContext& ctx) {
  auto& pool = world.template pool<MacGrid<d>>();
  const FluidSolverSettings& settings = world.template resource<FluidSolverSettings>();
  for (std::size_t g = 0; g < pool.size(); ++g) {
    MacGrid<d>& grid = pool.components()[g];
    const FluidMaterial* material = world.template get<FluidMaterial>(pool.entities()[g]);
    const double rho = material ? material->density : 1.0, mu = material ? material->viscosity : 0.0;

    // Rebuild the operators only when what they depend on changed (CFL steps change dt; a moving
    // obstacle changes the prescribed face velocities folded into them).
    Cache& c = *cache_;
    const auto kind = poissonPreconditionerKindOf(settings.preconditioner);
    const auto coupledKind = settings.coupledCutCorrection ? solvers::CoupledPreconditionerKind::CutCorrected
                                                           : solvers::CoupledPreconditionerKind::BlockDiagonal;
    if (!c.ops || c.dt != ctx.dt || c.density != rho || c.viscosity != mu || c.solid != grid.solid || c.kind != kind ||
        c.cutCorrection != settings.coupledCutCorrection ||
        c.wallDistance != grid.obstacleWallDistance || c.wallVelocity != grid.obstacleWallVelocity ||
        c.openFraction != grid.openFraction ||
        ((grid.obstaclesMove() || !c.motions.empty()) && c.motions != grid.obstacleMotions)) {
      c.ops = std::make_unique<solvers::FluidOperators<d>>(
          solvers::buildFluidOperators(fluidDomainOf(grid), solvers::FluidParameters{rho, mu, ctx.dt}));
      c.preconditioner = std::make_unique<solvers::PoissonPreconditioner<d>>(*c.ops, kind);
      c.cutCorrection = settings.coupledCutCorrection;
      c.coupled = settings.projection == FluidSolverSettings::Projection::Coupled
                      ? std::make_unique<solvers::CoupledPreconditioner<d>>(*c.ops, *c.preconditioner, coupledKind)
                      : nullptr;
      c.dt = ctx.dt;
      c.density = rho;
      c.viscosity = mu;
      c.solid = grid.solid;
      c.wallDistance = grid.obstacleWallDistance;
      c.wallVelocity = grid.obstacleWallVelocity;
      c.openFraction = grid.openFraction;
      c.motions = grid.obstaclesMove() ? grid.obstacleMotions : std::vector<ObstacleMotion<d>>{};
      c.kind = kind;
    }
    solvers::ProjectionSettings ps;
    ps.preconditioner = kind;
    ps.coupledPreconditioner = coupledKind;
    ps.solve.maxIterations = settings.maxIterations;
    ps.solve.relativeTolerance = settings.tolerance;
    ps.viscosity.maxIterations = settings.maxIterations;
    ps.viscosity.relativeTolerance = settings.tolerance;

    Eigen::VectorXd u = Eigen::Map<const Eigen::VectorXd>(grid.u.data(), grid.u.size());
    const solvers::ProjectionReport report =
        settings.projection == FluidSolverSettings::Projection::Chorin
            ? solvers::chorinProjection(*c.ops, u, ps, c.preconditioner.get())
            : solvers::coupledProjection(*c.ops, u, ps, c.preconditioner.get(), c.coupled.get());
    Eigen::Map<Eigen::VectorXd>(grid.u.data(), grid.u.size()) = u;
    for (std::size_t i = 0; i < grid.p.size(); ++i) grid.p[i] = report.pressure[static_cast<Eigen::Index>(i)];

    // Diagnostics of t^{n+1}.
    const auto& layout = c.ops->domain.layout;
    const Eigen::VectorXd divergence = solvers::constraintDivergence(*c.ops, u);  // cut faces weighted
    const double maxDivergence = divergence.size() > 0 ? divergence.cwiseAbs().maxCoeff() : 0.0;
    double kinetic = 0, change = 0;
    Eigen::Vector3d momentum = Eigen::Vector3d::Zero();
    const double faceMass = rho * layout.cellVolume();  // a face carries the mass of one cell
    for (int f = 0; f < layout.totalFaces(); ++f) {
      if (c.ops->domain.faces[f] == solvers::FaceKind::Inactive) continue;
      kinetic += 0.5 * faceMass * u[f] * u[f];
      momentum[layout.faceCoord(f).first] += faceMass * u[f];
      change = std::max(change, std::abs(u[f] - grid.uPrevious[f]));
    }
    grid.uPrevious = grid.u;
    auto& out = ctx.diagnostics;
    out.add("kinetic_energy", kinetic);
    out.add("total_energy", kinetic);
    out.add("linear_momentum_x", momentum.x());
    out.add("linear_momentum_y", momentum.y());
    out.add("linear_momentum_z", momentum.z());
    out.set("fluid_kinetic_energy", kinetic);
    out.set("fluid_solver_iterations", report.solve.iterations);
    out.set("fluid_solver_relative_residual", report.solve.relativeResidual());
    out.set("fluid_viscosity_iterations", report.viscosity.iterations);
    out.set("fluid_divergence_max", maxDivergence / layout.cellVolume());  // per unit volume: 1/s
    out.set("fluid_velocity_change", change / ctx.dt);                     // max |du|/dt
    out.set("fluid_cfl", (u.cwiseAbs().maxCoeff()) * ctx.dt / layout.dx);
  }
}

template class FluidProjection<2>;
template class FluidProjection<3>;

}  // namespace monolith
