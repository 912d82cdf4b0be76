#include "systems/fluid_obstacles.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

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

// Distance t in [0, tMax] along x + t e (|e| = 1) at which the ray enters the shape: 0 if x is
// inside, +inf if it misses within tMax.
template <int d>
double rayEntry(const Shape<d>& shape, const RigidBody<d>& body, const Eigen::Matrix<double, d, 1>& x,
                const Eigen::Matrix<double, d, 1>& e, double tMax) {
  constexpr double kMiss = std::numeric_limits<double>::infinity();
  const Eigen::Matrix<double, d, 1> p = body.rotation().transpose() * (x - body.x);
  const Eigen::Matrix<double, d, 1> q = body.rotation().transpose() * e;
  if (shape.type == ShapeType::Box) {  // slabs
    double lo = 0, hi = tMax;
    for (int i = 0; i < d; ++i) {
      const double h = shape.halfExtents[i];
      if (std::abs(q[i]) < 1e-15) {
        if (std::abs(p[i]) > h) return kMiss;
        continue;
      }
      double t0 = (-h - p[i]) / q[i], t1 = (h - p[i]) / q[i];
      if (t0 > t1) std::swap(t0, t1);
      lo = std::max(lo, t0), hi = std::min(hi, t1);
      if (lo > hi) return kMiss;
    }
    return lo;
  }
  const double r = shape.radius, b = p.dot(q), c = p.squaredNorm() - r * r;
  if (c <= 0) return 0;
  const double disc = b * b - c;
  if (disc < 0) return kMiss;
  const double t = -b - std::sqrt(disc);
  return t >= 0 && t <= tMax ? t : kMiss;
}

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

// Calls visit(g, a, f, b, dir) for every free face g = (a, f) (both cells inside the domain and
// not solid) and direction dir e_b whose next face that way touches a cell with marked[c] != 0:
// across the face's axis either cell of that face, along it the cell beyond (c1 + e_a or
// c0 - e_a). These are the viscous pairs that end on an obstacle face (operators.h).
template <int d, class Visit>
void forEachPairIntoMarkedCells(const solvers::MacLayout<d>& layout, const std::vector<std::uint8_t>& solid,
                                const std::vector<std::uint8_t>& marked, Visit&& visit) {
  using Index = typename solvers::MacLayout<d>::Index;
  const auto isMarked = [&](const Index& c) { return marked[layout.cellIndex(c)] != 0; };
  for (int g = 0; g < layout.totalFaces(); ++g) {
    const auto [a, f] = layout.faceCoord(g);
    Index c0, c1 = f;
    if (!layout.cellInside(c1) || !neighbour(layout, c1, a, -1, c0)) continue;  // a domain boundary face
    if (solid[layout.cellIndex(c0)] || solid[layout.cellIndex(c1)]) continue;   // not a free face
    for (int b = 0; b < d; ++b)
      for (int dir = -1; dir <= 1; dir += 2) {
        Index n0, n1;
        const bool hit = b == a ? (dir > 0 ? neighbour(layout, c1, a, 1, n1) && isMarked(n1)
                                           : neighbour(layout, c0, a, -1, n0) && isMarked(n0))
                                : (neighbour(layout, c0, b, dir, n0) && isMarked(n0)) ||
                                      (neighbour(layout, c1, b, dir, n1) && isMarked(n1));
        if (hit) visit(g, a, f, b, dir);
      }
  }
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
std::vector<double> obstacleWallDistances(const World<d>& world, const MacGrid<d>& grid) {
  using Index = typename solvers::MacLayout<d>::Index;
  const solvers::MacLayout<d> layout = macLayoutOf(grid);
  std::vector<std::pair<const Shape<d>*, const RigidBody<d>*>> obstacles;
  forEachObstacle(world, [&](Entity, const Shape<d>& shape, const RigidBody<d>& body) { obstacles.emplace_back(&shape, &body); });
  std::vector<double> distance(static_cast<std::size_t>(layout.totalFaces()) * 2 * d, 1.0);
  if (grid.solid.empty()) return distance;
  forEachPairIntoMarkedCells(layout, grid.solid, grid.solid, [&](int g, int a, const Index& f, int b, int dir) {
    Eigen::Matrix<double, d, 1> e = Eigen::Matrix<double, d, 1>::Zero();
    e[b] = dir;
    const auto x = layout.faceCenter(a, f);
    double t = std::numeric_limits<double>::infinity();
    for (const auto& [shape, body] : obstacles) t = std::min(t, rayEntry(*shape, *body, x, e, layout.dx));
    distance[static_cast<std::size_t>(g) * 2 * d + 2 * b + (dir > 0)] =
        std::clamp(t / layout.dx, solvers::FluidDomain<d>::kMinWallDistance, 1.0);
  });
  return distance;
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

  // Viscous stress, exactly as the viscous operator applies it (operators.h): every free face of
  // axis a whose next face along axis b is one of this obstacle's faces has a row
  // mu (u - u_wall) / (theta dx) on the face area, theta dx being the distance to the wall (the
  // grid's wall distances; 1 cell when the wall sits at the obstacle face's centre; along the
  // face's own axis the row is the normal stress of the cell between). The fluid loses that
  // momentum to the body, so the sum is the body's share of the discrete momentum balance (on a
  // staircase the normal rows do not vanish as du_n/dn = 0 would make them on a smooth wall).
  if (viscosity > 0) {
    const std::vector<double>& wallDistance = grid.obstacleWallDistance;
    forEachPairIntoMarkedCells(layout, grid.solid, mine, [&](int g, int a, const Index& fi, int b, int dir) {
      const double theta = wallDistance.empty() ? 1.0 : wallDistance[static_cast<std::size_t>(g) * 2 * d + 2 * b + (dir > 0)];
      // The operator's known value: the obstacle face's prescribed velocity (its centre, one cell away).
      Eigen::Matrix<double, d, 1> wallPoint = layout.faceCenter(a, fi);
      wallPoint[b] += dir * layout.dx;
      const double wall = grid.obstacleVelocityAt(wallPoint)[a];
      force[a] += viscosity * (grid.u[g] - wall) / (theta * layout.dx) * area;
    });
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
    if (world.settings().fluid.obstacleWallAtSurface) grid.obstacleWallDistance = obstacleWallDistances(world, grid);
    else grid.obstacleWallDistance.clear();
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
template std::vector<double> obstacleWallDistances<2>(const World<2>&, const MacGrid<2>&);
template std::vector<double> obstacleWallDistances<3>(const World<3>&, const MacGrid<3>&);
template Eigen::Vector2d obstacleForce<2>(const World<2>&, Entity, const MacGrid<2>&, double);
template Eigen::Vector3d obstacleForce<3>(const World<3>&, Entity, const MacGrid<3>&, double);
template class RasterizeObstacles<2>;
template class RasterizeObstacles<3>;
template class ObstacleForces<2>;
template class ObstacleForces<3>;

}  // namespace monolith
