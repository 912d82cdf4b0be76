#include "systems/fluid_obstacles.h"

#include <cmath>

#include "components/fluid_obstacle.h"
#include "solvers/mac_layout.h"
#include "systems/fluid_domain.h"

namespace monolith {

template <int d>
bool shapeContains(const Shape<d>& shape, const RigidBody<d>& body, const Eigen::Matrix<double, d, 1>& x) {
  const Eigen::Matrix<double, d, 1> local = body.rotation().transpose() * (x - body.x);
  if (shape.type == ShapeType::Box) return (local.cwiseAbs().array() <= shape.halfExtents.array()).all();
  return local.squaredNorm() <= shape.radius * shape.radius;
}

namespace {

// The cell next to c along `axis` in direction dir (+-1); false outside a non-periodic domain.
template <int d>
bool neighbour(const solvers::MacLayout<d>& layout, typename solvers::MacLayout<d>::Index c, int axis, int dir,
               typename solvers::MacLayout<d>::Index& out) {
  c[axis] += dir;
  if (layout.periodic[axis]) c[axis] = (c[axis] + layout.cells[axis]) % layout.cells[axis];
  if (!layout.cellInside(c)) return false;
  out = c;
  return true;
}

// Every entity with a fluid_obstacle, shape and rigid_body, in pool order.
template <int d, class F>
void forEachObstacle(const World<d>& world, F&& f) {
  const auto* pool = world.template findPool<FluidObstacle>();
  if (!pool) return;
  for (Entity e : pool->entities()) {
    const Shape<d>* shape = world.template get<Shape<d>>(e);
    const RigidBody<d>* body = world.template get<RigidBody<d>>(e);
    if (shape && body) f(e, *shape, *body);
  }
}

}  // namespace

template <int d>
std::vector<std::uint8_t> obstacleMask(const World<d>& world, const MacGrid<d>& grid) {
  const solvers::MacLayout<d> layout = macLayoutOf(grid);
  std::vector<std::uint8_t> mask(layout.cellCount(), 0);
  forEachObstacle(world, [&](Entity, const Shape<d>& shape, const RigidBody<d>& body) {
    for (int c = 0; c < layout.cellCount(); ++c)
      if (!mask[c] && shapeContains(shape, body, layout.cellCenter(layout.cellCoord(c)))) mask[c] = 1;
  });
  return mask;
}

template <int d>
Eigen::Matrix<double, d, 1> obstacleForce(const World<d>& world, Entity obstacle, const MacGrid<d>& grid,
                                          double viscosity) {
  using Vec = Eigen::Matrix<double, d, 1>;
  using Index = typename solvers::MacLayout<d>::Index;
  Vec force = Vec::Zero();
  const Shape<d>* shape = world.template get<Shape<d>>(obstacle);
  const RigidBody<d>* body = world.template get<RigidBody<d>>(obstacle);
  if (!shape || !body || grid.solid.empty()) return force;
  const solvers::MacLayout<d> layout = macLayoutOf(grid);
  const int n = layout.cellCount();
  // Cells of this obstacle: solid and with the centre inside its shape.
  std::vector<std::uint8_t> mine(n, 0);
  for (int c = 0; c < n; ++c)
    mine[c] = grid.solid[c] && shapeContains(*shape, *body, layout.cellCenter(layout.cellCoord(c)));
  const double area = layout.faceArea();

  // Pressure: p of the fluid cell times the face area, along the normal from fluid into solid.
  for (int s = 0; s < n; ++s) {
    if (!mine[s]) continue;
    const Index cs = layout.cellCoord(s);
    for (int a = 0; a < d; ++a)
      for (int dir = -1; dir <= 1; dir += 2) {
        Index cn;
        if (!neighbour(layout, cs, a, dir, cn)) continue;
        const int f = layout.cellIndex(cn);
        if (grid.solid[f]) continue;
        force[a] -= dir * grid.p[f] * area;
      }
  }

  // Wall shear: a free face of axis a (fluid on both sides) whose neighbours across axis b lie
  // in the obstacle has the no-slip wall at distance dx/2; stress mu (u - u_wall) / (dx/2) drags the body
  // along u. Weighted by the fraction of the face's span (half of each adjacent cell) covered.
  if (viscosity > 0) {
    for (int g = 0; g < layout.totalFaces(); ++g) {
      const auto [a, fi] = layout.faceCoord(g);
      Index c0, c1 = fi;
      if (!layout.cellInside(c1) || !neighbour(layout, c1, a, -1, c0)) continue;  // a domain boundary face
      if (grid.solid[layout.cellIndex(c0)] || grid.solid[layout.cellIndex(c1)]) continue;
      for (int b = 0; b < d; ++b) {
        if (b == a) continue;
        for (int dir = -1; dir <= 1; dir += 2) {
          Index n0, n1;
          double covered = 0;
          if (neighbour(layout, c0, b, dir, n0) && mine[layout.cellIndex(n0)]) covered += 0.5;
          if (neighbour(layout, c1, b, dir, n1) && mine[layout.cellIndex(n1)]) covered += 0.5;
          if (covered == 0) continue;
          // Relative to the wall's own velocity at the wall point (dx/2 away along b).
          Eigen::Matrix<double, d, 1> wallPoint = layout.faceCenter(a, fi);
          wallPoint[b] += dir * 0.5 * layout.dx;
          const double wall = grid.obstacleVelocityAt(wallPoint)[a];
          force[a] += viscosity * (grid.u[g] - wall) / (0.5 * layout.dx) * area * covered;
        }
      }
    }
  }
  return force;
}

template <int d>
std::vector<std::string> RasterizeObstacles<d>::reads() const {
  return {Shape<d>::kName, RigidBody<d>::kName, FluidObstacle::kName};
}

template <int d>
bool RasterizeObstacles<d>::needed(const World<d>& w) const {
  return w.template count<MacGrid<d>>() > 0 && w.template count<FluidObstacle>() > 0;
}

// Pose and rigid velocity of every obstacle (static: at rest; kinematic: its scripted motion).
template <int d>
std::vector<ObstacleMotion<d>> obstacleMotions(const World<d>& world) {
  std::vector<ObstacleMotion<d>> motions;
  forEachObstacle(world, [&](Entity, const Shape<d>& shape, const RigidBody<d>& body) {
    ObstacleMotion<d> m;
    m.centre = body.x;
    m.reach = shape.type == ShapeType::Box ? shape.halfExtents.norm() : shape.radius;
    if (!body.isStatic) {
      m.velocity = body.v;
      const AngularVec<d> w = body.omega();
      if constexpr (d == 3) m.angularVelocity = w;
      else m.angularVelocity.z() = w(0);
    }
    motions.push_back(m);
  });
  return motions;
}

template <int d>
void RasterizeObstacles<d>::run(World<d>& world, StepContext&) {
  auto& pool = world.template pool<MacGrid<d>>();
  const std::vector<ObstacleMotion<d>> motions = obstacleMotions(world);
  for (MacGrid<d>& grid : pool.components()) {
    grid.obstacleMotions = motions;
    std::vector<std::uint8_t> mask = obstacleMask(world, grid);
    if (mask != grid.solid) grid.solid = std::move(mask);  // unchanged: keep the projection's cache
  }
}

template <int d>
std::vector<std::string> ObstacleForces<d>::reads() const {
  return {Shape<d>::kName, RigidBody<d>::kName, FluidObstacle::kName, MacGrid<d>::kName, FluidMaterial::kName};
}

template <int d>
bool ObstacleForces<d>::needed(const World<d>& w) const {
  return w.template count<MacGrid<d>>() > 0 && w.template count<FluidObstacle>() > 0;
}

template <int d>
void ObstacleForces<d>::run(World<d>& world, StepContext& ctx) {
  const auto& pool = world.template pool<MacGrid<d>>();
  if (pool.size() == 0) return;
  const MacGrid<d>& grid = pool.components()[0];
  const FluidMaterial* material = world.template get<FluidMaterial>(pool.entities()[0]);
  const double mu = material ? material->viscosity : 0.0;
  const char* axes[] = {"x", "y", "z"};
  forEachObstacle(world, [&](Entity e, const Shape<d>&, const RigidBody<d>&) {
    const Eigen::Matrix<double, d, 1> f = obstacleForce(world, e, grid, mu);
    const std::string& name = world.name(e);
    const std::string prefix = "obstacle_" + (name.empty() ? std::to_string(e.index) : name) + "_force_";
    for (int a = 0; a < d; ++a) ctx.diagnostics.set(prefix + axes[a], f[a]);
  });
}

template bool shapeContains<2>(const Shape<2>&, const RigidBody<2>&, const Eigen::Vector2d&);
template bool shapeContains<3>(const Shape<3>&, const RigidBody<3>&, const Eigen::Vector3d&);
template std::vector<std::uint8_t> obstacleMask<2>(const World<2>&, const MacGrid<2>&);
template std::vector<std::uint8_t> obstacleMask<3>(const World<3>&, const MacGrid<3>&);
template Eigen::Vector2d obstacleForce<2>(const World<2>&, Entity, const MacGrid<2>&, double);
template Eigen::Vector3d obstacleForce<3>(const World<3>&, Entity, const MacGrid<3>&, double);
template class RasterizeObstacles<2>;
template class RasterizeObstacles<3>;
template class ObstacleForces<2>;
template class ObstacleForces<3>;

}  // namespace monolith
