#include "systems/fluid_domain.h"

namespace monolith {

template <int d>
solvers::MacLayout<d> macLayoutOf(const MacGrid<d>& grid) {
  std::array<bool, d> periodic{};
  for (int a = 0; a < d; ++a) periodic[a] = grid.periodic(a);
  return solvers::MacLayout<d>(grid.cells, grid.dx, grid.origin, periodic);
}

template <int d>
solvers::FluidDomain<d> fluidDomainOf(const MacGrid<d>& grid) {
  using Spec = solvers::SideSpec<d>;
  using Vec = Eigen::Matrix<double, d, 1>;
  const auto layout = macLayoutOf(grid);
  solvers::BoxSpec<d> box;
  for (int side = 0; side < 2 * d; ++side) {
    const SideCondition<d>& c = grid.sides[side];
    const int axis = side / 2;
    const double inward = side % 2 == 0 ? 1.0 : -1.0;
    switch (c.type) {
      case DomainSide::Wall: box[side] = Spec::wall(!c.slip, c.velocity); break;
      case DomainSide::Outflow: box[side] = Spec::outflow(); break;
      case DomainSide::Periodic: box[side] = Spec::periodic(); break;
      case DomainSide::Inflow:
        if (!c.parabolic) {
          box[side] = Spec::inflow(Vec(c.velocity));
        } else {
          const Vec lower = grid.origin;
          Vec extent;
          for (int a = 0; a < d; ++a) extent[a] = grid.cells[a] * grid.dx;
          const double peak = c.peakVelocity;
          box[side] = Spec::inflow(solvers::VelocityField<d>([=](const Vec& x) {
            double shape = 1;
            for (int b = 0; b < d; ++b) {
              if (b == axis) continue;
              const double s = x[b] - lower[b], h = extent[b];
              shape *= 4 * s * (h - s) / (h * h);
            }
            Vec v = Vec::Zero();
            v[axis] = inward * peak * shape;
            return v;
          }));
        }
        box[side].noSlip = !c.slip;
        break;
    }
  }
  solvers::FluidDomain<d> domain = solvers::boxDomain(layout, box);
  bool anySolid = false;
  for (auto s : grid.solid) anySolid = anySolid || s;
  if (anySolid || !grid.openFraction.empty()) {
    solvers::VelocityField<d> obstacleVelocity;
    if (grid.obstaclesMove()) obstacleVelocity = [&grid](const Vec& x) { return grid.obstacleVelocityAt(x); };
    solvers::markSolid(domain, grid.solid, obstacleVelocity);
    if (!grid.openFraction.empty()) solvers::cutFaces(domain, grid.openFraction, obstacleVelocity);
    domain.wallDistance = grid.obstacleWallDistance;
    domain.wallVelocity = grid.obstacleWallVelocity;
  }
  return domain;
}

template solvers::MacLayout<2> macLayoutOf<2>(const MacGrid<2>&);
template solvers::MacLayout<3> macLayoutOf<3>(const MacGrid<3>&);
template solvers::FluidDomain<2> fluidDomainOf<2>(const MacGrid<2>&);
template solvers::FluidDomain<3> fluidDomainOf<3>(const MacGrid<3>&);

}  // namespace monolith
