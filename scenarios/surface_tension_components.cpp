#include "scenarios/surface_tension_components.h"

#include <cmath>
#include <sstream>

#include "components/two_phase_flow.h"
#include "solvers/mac_layout.h"
#include "solvers/surface_tension/front.h"
#include "solvers/surface_tension/level_set_front.h"
#include "solvers/surface_tension/level_set_tracking.h"

namespace monolith {

namespace {

// "front": {"shape": "circle", "centre": [x, y], "radius": r, "epsilon": e, "mode": m, "points": n}
//          r (1 + e cos(m theta)), n points (default: one per dx of arc);
//       or {"shape": "polygon", "points": [[x, y], ...]} counter-clockwise around the inside phase.
solvers::Front2 parseFront(const Config& c, double dx) {
  const std::string shape = c.oneOf("shape", {"circle", "polygon"}, "");
  if (shape == "circle") {
    const Eigen::VectorXd centre = c.vector("centre", 2);
    const double radius = c.number("radius", Bound::Positive);
    const double epsilon = c.number("epsilon", 0.0);
    if (!(std::abs(epsilon) < 1)) c.failAt("epsilon", "a perturbation |epsilon| < 1", std::to_string(epsilon));
    const long mode = c.integer("mode", 2, 0, 1000);
    const long fallback = std::max(8L, std::lround(2 * M_PI * radius / dx));
    const long points = c.integer("points", fallback, 8, 10000000);
    return solvers::perturbedCircle(Eigen::Vector2d(centre[0], centre[1]), radius, epsilon, static_cast<int>(mode),
                                    static_cast<int>(points));
  }
  const Json& raw = c.raw().contains("points") ? c.raw()["points"] : Json();
  if (!raw.is_array() || raw.size() < 4)
    c.failAt("points", "an array of at least 4 points [x, y]", c.raw().contains("points") ? describeJson(raw) : "nothing");
  const Config list(raw, c.file(), c.pathOf("points"));
  std::vector<Eigen::Vector2d> points;
  for (std::size_t i = 0; i < raw.size(); ++i) {
    const Config p = list.element(i);
    if (!p.raw().is_array() || p.raw().size() != 2 || !p.raw()[0].is_number() || !p.raw()[1].is_number())
      p.fail("a point [x, y] of finite numbers", describeJson(p.raw()));
    points.emplace_back(p.raw()[0].get<double>(), p.raw()[1].get<double>());
  }
  c.markUsed("points");
  solvers::Front2 front = solvers::closedPolyline(points);
  if (!(solvers::enclosedArea(front) > 0))
    c.failAt("points", "a counter-clockwise polygon (positive area) around the inside phase", "a clockwise or empty one");
  return front;
}

template <int d>
void parseTwoPhaseFlow(World<d>& world, Entity e, const Config& c) {
  if constexpr (d != 2) {
    (void)world;
    (void)e;
    c.fail("a 2-D scene (\"dimension\": 2): surface tension fronts are implemented in 2-D only", "dimension 3");
  } else {
    TwoPhaseFlow<2> flow;
    const Eigen::VectorXd n = c.vector("cells", 2, Bound::Positive);
    for (int a = 0; a < 2; ++a) {
      if (n[a] != std::floor(n[a]) || n[a] < 4 || n[a] > 16384)
        c.failAt("cells[" + std::to_string(a) + "]", "an integer number of cells in [4, 16384]", std::to_string(n[a]));
      flow.cells[a] = static_cast<int>(n[a]);
    }
    const Eigen::VectorXd lo = c.vector("domain_min", Eigen::VectorXd::Zero(2));
    const Eigen::VectorXd hi = c.vector("domain_max", 2);
    flow.origin = lo;
    flow.dx = (hi[0] - lo[0]) / flow.cells[0];
    const double hy = (hi[1] - lo[1]) / flow.cells[1];
    if (!(flow.dx > 0) || !(hy > 0)) c.failAt("domain_max", "a domain_max above domain_min on every axis", "");
    if (std::abs(hy - flow.dx) > 1e-9 * flow.dx) {
      std::ostringstream got;
      got << "dx = " << flow.dx << " along x but " << hy << " along y";
      c.failAt("cells", "square cells: (domain_max - domain_min) / cells equal on both axes", got.str());
    }
    flow.onePhase = c.oneOf("phases", {"one", "two"}, "two") == "one";
    flow.densityInside = c.number("density_inside", Bound::Positive);
    if (flow.onePhase) {
      if (c.has("density_outside"))
        c.failAt("density_outside", "no outside density with \"phases\": \"one\" (the outside is Dirichlet air)",
                 describeJson(c.raw()["density_outside"]));
    } else {
      flow.densityOutside = c.number("density_outside", Bound::Positive);
    }
    flow.viscosity = c.number("viscosity", 0.0, Bound::NonNegative);
    if (c.has("viscosity_outside") && c.number("viscosity_outside", Bound::NonNegative) != flow.viscosity)
      c.failAt("viscosity_outside",
               "the same viscosity as \"viscosity\": the implicit solve (6.33) factors one viscosity for both phases "
               "(a viscosity jump would need an explicit viscous step, which is not implemented)",
               describeJson(c.raw()["viscosity_outside"]));
    flow.sigma = c.number("surface_tension", Bound::NonNegative);
    flow.implicitSurfaceTension = c.oneOf("treatment", {"implicit", "explicit"}, "implicit") == "implicit";
    const Eigen::VectorXd g = c.vector("gravity", Eigen::VectorXd::Zero(2));
    flow.gravity = g;
    const std::string advection = c.oneOf("advection", {"semi_lagrangian", "eno_rk3", "none"}, "semi_lagrangian");
    flow.advect = advection == "none" ? 0 : advection == "eno_rk3" ? 2 : 1;
    flow.advectionCfl = c.number("advection_cfl", 0.0, Bound::NonNegative);
    flow.blowUpSpeed = c.number("blow_up_speed", 1e3, Bound::Positive);
    flow.tolerance = c.number("tolerance", 1e-12, Bound::Positive);
    if (c.has("remesh") && c.raw()["remesh"].is_boolean()) {
      // "remesh": false keeps the front's points as given (the original driver's static circle).
      flow.remesh = c.raw()["remesh"].get<bool>() ? 1 : 0;
      c.markUsed("remesh");
    } else if (c.has("remesh")) {
      const Config r = c.child("remesh");
      flow.minSegment = r.number("min", 0.5, Bound::Positive);
      flow.maxSegment = r.number("max", 1.5, Bound::Positive);
      if (!(flow.maxSegment > 2 * flow.minSegment))
        r.failAt("max", "max > 2 min (a split segment must not fall below min)", std::to_string(flow.maxSegment));
      r.finish();
    }
    const Config f = c.child("front");
    const std::string tracking = f.oneOf("tracking", {"front", "level_set", "level_set_implicit"}, "front");
    flow.levelSetFront = tracking == "front" ? 0 : tracking == "level_set" ? 1 : 2;
    // Where a coupling face's u* comes from (docs/surface_tension.md, step 3): sampled from the grid
    // each step, or carried on the front's points from the last solve. A level-set front's mesh is
    // rebuilt every step, so it has no points to carry velocities on.
    flow.carryCouplingVelocity = c.oneOf("coupling_velocity", {"sampled", "carried"}, "sampled") == "carried";
    if (flow.carryCouplingVelocity && flow.levelSetFront)
      c.failAt("coupling_velocity",
               "\"sampled\" with a level-set-tracked front (\"carried\" needs \"tracking\": \"front\": a level set's mesh "
               "is rebuilt every step, so no point keeps its velocity)",
               "\"carried\" with \"tracking\": \"" + tracking + "\"");
    // How a level-set-tracked front's phi is kept a distance (docs/surface_tension.md, step 5).
    for (const char* key : {"redistancing", "keep", "particles"})
      if (!flow.levelSetFront && f.has(key))
        f.failAt(key, "no \"" + std::string(key) + "\" with \"tracking\": \"front\" (it sets how a level set is kept)",
                 "\"" + std::string(key) + "\" with front tracking");
    const std::string redistancing = f.oneOf("redistancing", {"to_mesh", "fast_marching", "none"}, "to_mesh");
    flow.levelSetRedistancing = redistancing == "to_mesh" ? 0 : redistancing == "fast_marching" ? 1 : 2;
    flow.levelSetKeep = f.number("keep", flow.levelSetKeep, Bound::NonNegative);
    flow.particleLevelSet = f.boolean("particles", false) ? 1 : 0;
    if (flow.particleLevelSet && flow.levelSetFront == 2)
      f.failAt("particles", "false with \"tracking\": \"level_set_implicit\" (its phi is not advected, so no particle corrects it)",
               "true");
    if (f.has("reseed_every") && !flow.particleLevelSet)
      f.failAt("reseed_every", "no \"reseed_every\" without \"particles\": true (it reseeds the particle level set's particles)",
               "\"reseed_every\" without particles");
    flow.particleReseedEvery = static_cast<int>(f.integer("reseed_every", 0, 0, 1000000000));
    solvers::Front2 front = parseFront(f, flow.dx);
    const Eigen::Vector2d upper = flow.origin + flow.dx * flow.cells.cast<double>();
    for (const auto& x : front.points)
      if ((x.array() <= flow.origin.array()).any() || (x.array() >= upper.array()).any())
        f.fail("a front strictly inside the domain", "a point at (" + std::to_string(x.x()) + ", " + std::to_string(x.y()) + ")");
    f.finish();
    const solvers::MacLayout<2> layout(flow.cells, flow.dx, flow.origin);
    if (flow.levelSetFront) {
      // The level set: the signed distance to the front (a circle's polygon refined 16x first, so
      // the distance is the circle's to ~1e-4 dx), and the mesh rebuilt from it.
      solvers::Front2 fine = front;
      if (f.raw().value("shape", std::string()) == "circle") {
        const Eigen::VectorXd centre = f.vector("centre", 2);
        fine = solvers::perturbedCircle(Eigen::Vector2d(centre[0], centre[1]), f.number("radius"), f.number("epsilon", 0.0),
                                        static_cast<int>(f.integer("mode", 2, 0, 1000)), 16 * front.pointCount());
      }
      flow.phi = solvers::signedDistanceToFront(layout, fine);
      front = solvers::frontFromLevelSet(layout, flow.phi, solvers::CrossingOrder::Fourth);
    }
    for (const auto& x : front.points) flow.frontPoints.insert(flow.frontPoints.end(), {x.x(), x.y()});
    for (const auto& el : front.elements) flow.frontElements.insert(flow.frontElements.end(), {el[0], el[1]});
    flow.initialArea = solvers::enclosedArea(front);
    flow.u.assign(layout.totalFaces(), 0.0);
    flow.pInside.assign(layout.cellCount(), 0.0);
    flow.pOutside.assign(layout.cellCount(), 0.0);
    if (c.has("probes")) {
      const Json& raw = c.raw()["probes"];
      if (!raw.is_array()) c.failAt("probes", "an array of {name, position}", describeJson(raw));
      const Config list(raw, c.file(), c.pathOf("probes"));
      for (std::size_t i = 0; i < raw.size(); ++i) {
        const Config p = list.element(i);
        const std::string name = p.string("name");
        if (name.empty() || name.find(',') != std::string::npos) p.failAt("name", "a non-empty name without commas", name);
        const Eigen::VectorXd x = p.vector("position", 2);
        p.finish();
        flow.probePoints.insert(flow.probePoints.end(), {x[0], x[1]});
        flow.probeNames += (flow.probeNames.empty() ? "" : ",") + name;
      }
      c.markUsed("probes");
    }
    world.add(e, flow);
  }
}

}  // namespace

template <int d>
void registerSurfaceTensionComponents(Registry& r) {
  r.addComponentOf<d, TwoPhaseFlow<d>>(
      "one- or two-phase flow with surface tension on a Lagrangian front (2-D): cells, domain_min/max, phases "
      "(one|two), density_inside/outside, viscosity, surface_tension, treatment (implicit|explicit), gravity, "
      "advection, coupling_velocity (sampled|carried), front {shape: circle|polygon, tracking: "
      "front|level_set|level_set_implicit, redistancing: to_mesh|fast_marching|none, keep, particles, reseed_every}, probes [{name, position}]",
      parseTwoPhaseFlow<d>);
}

template void registerSurfaceTensionComponents<2>(Registry&);
template void registerSurfaceTensionComponents<3>(Registry&);

}  // namespace monolith
