#include "scenarios/fluid_components.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <sstream>

#include "components/deformable.h"
#include "components/fluid_coupling.h"
#include "components/fluid_obstacle.h"
#include "components/kinematic.h"
#include "components/level_set.h"
#include "components/mac_grid.h"
#include "components/rigid_body.h"
#include "components/shape.h"
#include "scenarios/level_set_component.h"
#include "solvers/mac_layout.h"
#include "systems/obstacle_geometry.h"

namespace monolith {

namespace {

const char* kAxisNames[] = {"x", "y", "z"};

std::string sideName(int side) { return std::string(kAxisNames[side / 2]) + (side % 2 ? "_max" : "_min"); }

template <int d>
SideCondition<d> parseSide(const Config& c) {
  SideCondition<d> s;
  const std::string type = c.oneOf("type", {"wall", "inflow", "outflow", "periodic"}, "");
  if (type == "wall") {
    s.type = DomainSide::Wall;
    s.slip = c.boolean("slip", false);
    s.velocity = c.vector("velocity", Eigen::VectorXd::Zero(d));  // a moving wall (cavity lid)
  } else if (type == "inflow") {
    s.type = DomainSide::Inflow;
    s.slip = c.boolean("slip", false);  // tangential velocity free (zero shear) instead of prescribed
    s.parabolic = c.oneOf("profile", {"uniform", "parabolic"}, "uniform") == "parabolic";
    if (s.parabolic) s.peakVelocity = c.number("peak_velocity");
    else s.velocity = c.vector("velocity", d);
  } else if (type == "outflow") {
    s.type = DomainSide::Outflow;
  } else {
    s.type = DomainSide::Periodic;
  }
  return s;
}

// Initial face velocities: zero, uniform, the Taylor-Green vortex (REFERENCES.md:
// u = A sin x cos y, v = -A cos x sin y; in 3-D times cos z, w = 0), or in 2-D the stream function
// psi = psi0 sin(k_x x) sin(k_y y) of the oscillating disk (thesis Sec. 5.11.6), u = dpsi/dy,
// v = -dpsi/dx, taken as differences of psi at the face's corners (discretely divergence free).
template <int d>
void initialVelocity(const Config& c, MacGrid<d>& grid, const solvers::MacLayout<d>& layout) {
  const std::string type = c.oneOf("type", {"zero", "uniform", "taylor_green", "stream_function"}, "zero");
  Eigen::Matrix<double, d, 1> uniform = Eigen::Matrix<double, d, 1>::Zero();
  double amplitude = 1;
  Eigen::VectorXd k = Eigen::VectorXd::Zero(2);
  if (type == "uniform") uniform = c.vector("velocity", d);
  if (type == "taylor_green") amplitude = c.number("amplitude", 1.0);
  if (type == "stream_function") {
    if (d != 2) c.failAt("type", "\"stream_function\" in a 2-D scene", "a 3-D scene");
    amplitude = c.number("psi0");
    k = c.vector("k", 2);
  }
  auto psi = [&](double x, double y) { return amplitude * std::sin(k[0] * x) * std::sin(k[1] * y); };
  for (int f = 0; f < layout.totalFaces(); ++f) {
    const auto [axis, index] = layout.faceCoord(f);
    const Eigen::Matrix<double, d, 1> x = layout.faceCenter(axis, index);
    double value = 0;
    if (type == "stream_function") {
      const double h = 0.5 * layout.dx;
      value = axis == 0 ? (psi(x[0], x[1] + h) - psi(x[0], x[1] - h)) / layout.dx
                        : -(psi(x[0] + h, x[1]) - psi(x[0] - h, x[1])) / layout.dx;
    }
    if (type == "uniform") value = uniform[axis];
    if (type == "taylor_green") {
      const double z = d == 3 ? std::cos(x[d - 1]) : 1.0;
      if (axis == 0) value = amplitude * std::sin(x[0]) * std::cos(x[1]) * z;
      if (axis == 1) value = -amplitude * std::cos(x[0]) * std::sin(x[1]) * z;
    }
    grid.u[f] = value;
  }
}

template <int d>
void parseMacGrid(World<d>& world, Entity e, const Config& c) {
  MacGrid<d> grid;
  const Eigen::VectorXd n = c.vector("cells", d, Bound::Positive);
  for (int a = 0; a < d; ++a) {
    if (n[a] != std::floor(n[a]) || n[a] < 2 || n[a] > 65536)
      c.failAt("cells[" + std::to_string(a) + "]", "an integer number of cells in [2, 65536]", std::to_string(n[a]));
    grid.cells[a] = static_cast<int>(n[a]);
  }
  const Eigen::VectorXd lo = c.vector("domain_min", Eigen::VectorXd::Zero(d));
  const Eigen::VectorXd hi = c.vector("domain_max", d);
  grid.origin = lo;
  grid.dx = (hi[0] - lo[0]) / grid.cells[0];
  for (int a = 0; a < d; ++a) {
    const double h = (hi[a] - lo[a]) / grid.cells[a];
    if (!(h > 0)) c.failAt("domain_max", "a domain_max above domain_min on every axis", "");
    if (std::abs(h - grid.dx) > 1e-9 * grid.dx) {
      std::ostringstream got;
      got << "dx = " << grid.dx << " along x but " << h << " along " << kAxisNames[a];
      c.failAt("cells", "square cells: (domain_max - domain_min) / cells equal on every axis", got.str());
    }
  }
  if (c.has("boundaries")) {
    const Config b = c.child("boundaries");
    for (int side = 0; side < 2 * d; ++side)
      if (b.has(sideName(side))) grid.sides[side] = parseSide<d>(b.child(sideName(side)));
    for (int a = 0; a < d; ++a) {
      const bool lower = grid.sides[2 * a].type == DomainSide::Periodic;
      const bool upper = grid.sides[2 * a + 1].type == DomainSide::Periodic;
      if (lower != upper)
        b.failAt(sideName(lower ? 2 * a + 1 : 2 * a), "\"periodic\" like the opposite side (periodicity pairs sides)",
                 "another type");
    }
    b.finish();
  }
  std::array<bool, d> periodic{};
  for (int a = 0; a < d; ++a) periodic[a] = grid.periodic(a);
  const solvers::MacLayout<d> layout(grid.cells, grid.dx, grid.origin, periodic);
  if (static_cast<double>(layout.totalFaces()) > 2e8)
    c.failAt("cells", "a grid of at most 2e8 faces", std::to_string(layout.totalFaces()) + " faces");
  grid.u.assign(layout.totalFaces(), 0.0);
  grid.p.assign(layout.cellCount(), 0.0);
  grid.solid.assign(layout.cellCount(), 0);
  if (c.has("initial_velocity")) {
    const Config init = c.child("initial_velocity");
    initialVelocity(init, grid, layout);
    init.finish();
  }
  grid.uPrevious = grid.u;
  world.add(e, std::move(grid));
}

template <int d>
void parseFluidMaterial(World<d>& world, Entity e, const Config& c) {
  if (!world.template has<MacGrid<d>>(e)) c.fail("fluid_material on the entity that has the mac_grid", "no mac_grid");
  FluidMaterial m;
  m.density = c.number("density", Bound::Positive);
  m.viscosity = c.number("viscosity", 0.0, Bound::NonNegative);
  world.add(e, m);
}

// An obstacle in the fluid: needs the entity's level_set or shape and a static or kinematic
// rigid_body (parsed before this component; registerFluidComponents runs after their
// registration, and registers level_set first).
template <int d>
void parseFluidObstacle(World<d>& world, Entity e, const Config& c) {
  const Shape<d>* shape = world.template get<Shape<d>>(e);
  const bool levelSet = world.template has<LevelSet<d>>(e);
  if (!shape && !levelSet) c.fail("fluid_obstacle on an entity with a \"level_set\" or a \"shape\"", "neither");
  const RigidBody<d>* body = world.template get<RigidBody<d>>(e);
  if (!body) c.fail("fluid_obstacle on an entity with a \"rigid_body\" (its position/orientation)", "no rigid_body");
  // The fluid does not push obstacles (one-way coupling): they are static or scripted.
  if (!body->isStatic && !world.template has<KinematicMotion<d>>(e))
    c.fail("fluid_obstacle on a static rigid_body (\"static\": true) or a kinematic one (one-way coupling)",
           "a dynamic rigid_body");
  // With a level set the fluid sees it; the shape (if any) is then only for contact and frames.
  if (!levelSet && !ObstacleGeometry<d>::supports(shape->type))
    c.fail("fluid_obstacle on a " + ObstacleGeometry<d>::supportedNames() + " shape, or on an entity with a \"level_set\"",
           "another shape type");
  world.add(e, FluidObstacle{});
}

// Linear interpolation of the MAC grid's face velocities at x (each component from its own face
// lattice, clamped to the grid).
template <int d>
Eigen::Matrix<double, d, 1> gridVelocityAt(const MacGrid<d>& grid, const Eigen::Matrix<double, d, 1>& x) {
  std::array<bool, d> periodic{};
  for (int a = 0; a < d; ++a) periodic[a] = grid.periodic(a);
  const solvers::MacLayout<d> layout(grid.cells, grid.dx, grid.origin, periodic);
  Eigen::Matrix<double, d, 1> out;
  for (int a = 0; a < d; ++a) {
    const auto dims = layout.faceDims(a);
    Eigen::Matrix<int, d, 1> base;
    Eigen::Matrix<double, d, 1> t;
    for (int b = 0; b < d; ++b) {
      const double s = (x[b] - grid.origin[b]) / grid.dx - (b == a ? 0.0 : 0.5);
      const int last = std::max(0, dims[b] - 2);
      base[b] = std::clamp(static_cast<int>(std::floor(s)), 0, last);
      t[b] = dims[b] < 2 ? 0.0 : std::clamp(s - base[b], 0.0, 1.0);
    }
    double value = 0;
    for (int corner = 0; corner < (1 << d); ++corner) {
      Eigen::Matrix<int, d, 1> f = base;
      double w = 1;
      for (int b = 0; b < d; ++b) {
        const int up = (corner >> b) & 1;
        f[b] = std::min(f[b] + up, dims[b] - 1);
        w *= up ? t[b] : 1 - t[b];
      }
      value += w * grid.u[layout.faceIndex(a, f)];
    }
    out[a] = value;
  }
  return out;
}

// Two-way coupling of a deformable body (its particles and mesh, parsed before this component):
// "velocity_from_fluid": true starts the particles with the velocity of the fluid around them
// (the grid's initial_velocity; the grid's entity must come earlier in the file).
template <int d>
void parseDeformableFluidCoupling(World<d>& world, Entity e, const Config& c, Particles<d>& p) {
  if (world.template has<RigidBinding<d>>(e))
    c.fail("fluid_coupling on a deformable body without \"bind\" (bound particles are not coupled)", "bound particles");
  if (c.boolean("velocity_from_fluid", false)) {
    const auto* grids = world.template findPool<MacGrid<d>>();
    if (!grids || grids->size() == 0)
      c.failAt("velocity_from_fluid", "a mac_grid entity listed before this one", "none");
    const MacGrid<d>& grid = grids->components()[0];
    for (int i = 0; i < p.count(); ++i) {
      if (p.fixed[i]) continue;
      const Eigen::Matrix<double, d, 1> v = gridVelocityAt(grid, Eigen::Matrix<double, d, 1>(Eigen::Map<const Eigen::Matrix<double, d, 1>>(&p.x[d * i])));
      for (int a = 0; a < d; ++a) p.v[d * i + a] = v[a];
    }
  }
  FluidCoupling<d> coupling;
  // "track": a point; the particle nearest it at the start is reported every step.
  if (c.has("track")) {
    const Eigen::VectorXd at = c.vector("track", d);
    double best = std::numeric_limits<double>::infinity();
    for (int i = 0; i < p.count(); ++i) {
      const double dist = (Eigen::Map<const Eigen::Matrix<double, d, 1>>(&p.x[d * i]) - at).norm();
      if (dist < best) {
        best = dist;
        coupling.trackParticle = i;
      }
    }
  }
  c.finish();
  world.add(e, coupling);
}

// Two-way coupling: a dynamic (or static: infinite mass) rigid_body with a shape the
// rasterization knows (or a level_set), or a deformable body.
template <int d>
void parseFluidCoupling(World<d>& world, Entity e, const Config& c) {
  if (Particles<d>* p = world.template get<Particles<d>>(e); p && !world.template has<RigidBody<d>>(e)) {
    if (world.template has<FluidObstacle>(e))
      c.fail("either fluid_obstacle (one-way) or fluid_coupling (two-way) on one entity", "both");
    parseDeformableFluidCoupling(world, e, c, *p);
    return;
  }
  const Shape<d>* shape = world.template get<Shape<d>>(e);
  const bool levelSet = world.template has<LevelSet<d>>(e);
  if (!shape && !levelSet) c.fail("fluid_coupling on an entity with a \"level_set\" or a \"shape\"", "neither");
  const RigidBody<d>* body = world.template get<RigidBody<d>>(e);
  if (!body) c.fail("fluid_coupling on an entity with a dynamic or static \"rigid_body\"", "no rigid_body");
  // A static body is coupled as an infinite-mass structure (at rest; its force is reported); a
  // scripted one stays one-way.
  if (world.template has<KinematicMotion<d>>(e))
    c.fail("fluid_coupling on a dynamic or static rigid_body (kinematic bodies are one-way: \"fluid_obstacle\")",
           "a kinematic rigid_body");
  if (world.template has<FluidObstacle>(e))
    c.fail("either fluid_obstacle (one-way) or fluid_coupling (two-way) on one entity", "both");
  if (!levelSet && !ObstacleGeometry<d>::supports(shape->type))
    c.fail("fluid_coupling on a " + ObstacleGeometry<d>::supportedNames() + " shape, or on an entity with a \"level_set\"",
           "another shape type");
  c.finish();
  world.add(e, FluidCoupling<d>{});
}

// How the monolithic fluid-structure system is solved (on the mac_grid's entity).
template <int d>
void parseFsiSolver(World<d>& world, Entity e, const Config& c) {
  if (!world.template has<MacGrid<d>>(e)) c.fail("fsi_solver on the entity with the \"mac_grid\"", "no mac_grid");
  FsiSolver s;
  const std::string p = c.oneOf("preconditioner", {"none", "block_jacobi", "block_exact", "schur"}, "schur");
  s.preconditioner = p == "none"           ? FsiSolver::Preconditioner::None
                     : p == "block_jacobi" ? FsiSolver::Preconditioner::BlockJacobi
                     : p == "schur"        ? FsiSolver::Preconditioner::Schur
                                           : FsiSolver::Preconditioner::BlockExact;
  s.halfStep = c.boolean("half_step", true);
  s.bodyVolumeBuoyancy = c.oneOf("buoyancy", {"structure_cells", "body_volume"}, "structure_cells") == "body_volume";
  c.finish();
  world.add(e, s);
}

}  // namespace

template <int d>
void registerFluidComponents(Registry& r) {
  r.addComponentOf<d, MacGrid<d>>(
      "fluid MAC grid: cells, domain_min/max, boundaries {x_min: wall|inflow|outflow|periodic, ...}, initial_velocity",
      parseMacGrid<d>);
  r.addComponentOf<d, FluidMaterial>("fluid density and dynamic viscosity (on the mac_grid entity)",
                                     parseFluidMaterial<d>);
  r.addComponentOf<d, LevelSet<d>>(
      "signed distance (negative inside) in the body frame, for fluid obstacles: {origin, spacing, samples, values "
      "(x fastest)}, {file (JSON of those)} or " + std::string(d == 2 ? "{polygon, spacing}" : "{mesh (OBJ), scale, spacing}"),
      parseLevelSetComponent<d>);
  r.addComponentOf<d, FluidObstacle>(
      "obstacle in the fluid: the entity's level_set, else its shape (" + ObstacleGeometry<d>::supportedNames() +
          "), at its static or kinematic rigid_body pose",
      parseFluidObstacle<d>);
  r.addComponentOf<d, FsiSolver>(
      "on the mac_grid entity: the fluid-structure solve's preconditioner (none, block_jacobi, block_exact, schur) and "
      "half_step (Sec. 5.4 steps 1-3)",
      parseFsiSolver<d>);
}

// After the rigid and deformable components: fluid_coupling reads the entity's rigid_body and
// shape, or its particles and mesh.
template <int d>
void registerFluidCouplingComponent(Registry& r) {
  r.addComponentOf<d, FluidCoupling<d>>(
      "two-way coupling of a dynamic rigid body (its shape (" + ObstacleGeometry<d>::supportedNames() +
          ") or level_set) or of a deformable body (velocity_from_fluid) with the fluid in one SPD solve (thesis Sec. "
          "5.4-5.8)",
      parseFluidCoupling<d>);
}

template void registerFluidCouplingComponent<2>(Registry&);
template void registerFluidCouplingComponent<3>(Registry&);
template void registerFluidComponents<2>(Registry&);
template void registerFluidComponents<3>(Registry&);

}  // namespace monolith
