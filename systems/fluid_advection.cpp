#include "systems/fluid_advection.h"

#include <limits>

#include "solvers/advection/cfl.h"
#include "solvers/advection/eno.h"
#include "solvers/advection/semi_lagrangian.h"
#include "solvers/advection/wall_ghosts.h"
#include "systems/fluid_domain.h"

namespace monolith {

namespace {
// Prescribed faces (walls, inflow, obstacles), solid cells and (ghostsAtSurface) the ghost rules of
// the obstacle walls as the advection schemes see them.
template <int d>
solvers::FaceBoundary faceBoundaryOf(const solvers::FluidDomain<d>& domain, bool ghostsAtSurface) {
  solvers::FaceBoundary b;
  const int faces = domain.layout.totalFaces();
  b.prescribedFace.assign(faces, 0);
  b.prescribedVelocity = Eigen::VectorXd::Zero(faces);
  bool anySolid = false;
  for (int f = 0; f < faces; ++f)
    if (domain.faces[f] == solvers::FaceKind::Prescribed) {
      b.prescribedFace[f] = 1;
      b.prescribedVelocity[f] = domain.faceVelocity[f];
    }
  std::vector<std::uint8_t> solid(domain.cells.size(), 0);
  for (std::size_t c = 0; c < solid.size(); ++c) {
    solid[c] = domain.cells[c] == solvers::CellKind::Solid;
    anySolid = anySolid || solid[c];
  }
  if (anySolid) b.solidCell = std::move(solid);
  if (ghostsAtSurface) b.ghosts = solvers::obstacleWallGhosts(domain);  // the wall where the viscous operator has it
  return b;
}
}  // namespace

template <int d>
void FluidAdvection<d>::run(World<d>& world, StepContext& ctx) {
  auto& pool = world.template pool<MacGrid<d>>();
  for (auto& grid : pool.components()) {
    const auto domain = fluidDomainOf(grid);
    const solvers::FaceBoundary boundary = faceBoundaryOf(domain, world.template resource<FluidSolverSettings>().advectionWallAtSurface);
    const Eigen::VectorXd u = Eigen::Map<const Eigen::VectorXd>(grid.u.data(), grid.u.size());
    const auto scheme = world.template resource<FluidSolverSettings>().advection;
    const Eigen::VectorXd advected =
        scheme == FluidSolverSettings::Advection::Eno3 ? solvers::advectFacesEnoRk3(domain.layout, u, ctx.dt, boundary)
        : scheme == FluidSolverSettings::Advection::Weno5
            ? solvers::advectFacesEnoRk3(domain.layout, u, ctx.dt, boundary, solvers::HjStencil::Weno5)
        : scheme == FluidSolverSettings::Advection::MacCormack ? solvers::advectFacesMacCormack(domain.layout, u, ctx.dt, boundary)
                                                               : solvers::advectFacesSemiLagrangian(domain.layout, u, ctx.dt, boundary);
    Eigen::Map<Eigen::VectorXd>(grid.u.data(), grid.u.size()) = advected;
  }
}

template <int d>
double FluidAdvection<d>::unitCflDt(const World<d>& world) const {
  double dt = std::numeric_limits<double>::infinity();
  if (const auto* pool = world.template findPool<MacGrid<d>>())
    for (const auto& grid : pool->components()) {
      const Eigen::VectorXd u = Eigen::Map<const Eigen::VectorXd>(grid.u.data(), grid.u.size());
      // Prescribed faces count with their prescribed speed: a flow started from rest by an
      // inflow, a moving lid or a moving obstacle must not take its first step at dt_max.
      const auto domain = fluidDomainOf(grid);
      dt = std::min(dt, solvers::cflTimeStep(domain.layout, u, 1.0, std::numeric_limits<double>::infinity(),
                                             faceBoundaryOf(domain, false)));
    }
  return dt;
}

template <int d>
void FluidGravity<d>::run(World<d>& world, StepContext& ctx) {
  const Vec<d> g = world.settings().gravity;
  for (auto& grid : world.template pool<MacGrid<d>>().components()) {
    const auto domain = fluidDomainOf(grid);
    for (int f = 0; f < domain.layout.totalFaces(); ++f)
      if (domain.faces[f] == solvers::FaceKind::Free) grid.u[f] += ctx.dt * g[domain.layout.faceCoord(f).first];
  }
}

template class FluidAdvection<2>;
template class FluidAdvection<3>;
template class FluidGravity<2>;
template class FluidGravity<3>;

}  // namespace monolith
