#include "systems/surface_tension_flow.h"

#include <iostream>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "solvers/surface_tension/front_metrics.h"
#include "solvers/surface_tension/two_phase_flow.h"

namespace monolith {

namespace {
std::vector<std::string> splitNames(const std::string& joined) {
  std::vector<std::string> names;
  std::stringstream s(joined);
  for (std::string name; std::getline(s, name, ',');) names.push_back(name);
  return names;
}
}  // namespace

template <int d>
void SurfaceTensionFlow<d>::run(World<d>& world, StepContext& ctx) {
  if constexpr (d != 2) {
    (void)world;
    (void)ctx;
    throw std::logic_error("surface_tension_flow: only 2-D fronts are implemented");
  } else {
    auto& pool = world.template pool<TwoPhaseFlow<2>>();
    for (std::size_t g = 0; g < pool.size(); ++g) {
      TwoPhaseFlow<2>& flow = pool.components()[g];
      solvers::TwoPhaseState state;
      state.layout = solvers::MacLayout<2>(flow.cells, flow.dx, flow.origin);
      state.u = Eigen::Map<const Eigen::VectorXd>(flow.u.data(), static_cast<Eigen::Index>(flow.u.size()));
      for (std::size_t k = 0; k + 1 < flow.frontPoints.size(); k += 2)
        state.front.points.emplace_back(flow.frontPoints[k], flow.frontPoints[k + 1]);
      for (std::size_t k = 0; k + 1 < flow.frontElements.size(); k += 2)
        state.front.elements.push_back({flow.frontElements[k], flow.frontElements[k + 1]});
      state.pInside = flow.pInside;
      state.pOutside = flow.pOutside;
      state.phi = flow.phi;
      for (std::size_t k = 0; k + 1 < flow.frontPointVelocity.size(); k += 2)
        state.pointVelocity.emplace_back(flow.frontPointVelocity[k], flow.frontPointVelocity[k + 1]);
      for (std::size_t k = 0; k + 3 < flow.levelSetParticles.size(); k += 4) {
        const double* q = flow.levelSetParticles.data() + k;
        state.levelSetParticles.push_back({Eigen::Vector2d(q[0], q[1]), q[2], q[3] < 0 ? -1 : 1});
      }
      state.time = ctx.time;
      state.step = static_cast<int>(ctx.step);

      solvers::TwoPhaseSettings s;
      s.densityInside = flow.densityInside;
      s.densityOutside = flow.densityOutside;
      s.onePhase = flow.onePhase != 0;
      s.viscosity = flow.viscosity;
      s.sigma = flow.sigma;
      s.implicitSurfaceTension = flow.implicitSurfaceTension != 0;
      s.gravity = flow.gravity;
      s.advection = flow.advect == 0   ? solvers::TwoPhaseAdvection::None
                    : flow.advect == 2 ? solvers::TwoPhaseAdvection::EnoRk3
                                       : solvers::TwoPhaseAdvection::SemiLagrangian;
      s.remesh = flow.remesh != 0;
      s.advectionCfl = flow.advectionCfl;
      s.minSegment = flow.minSegment;
      s.maxSegment = flow.maxSegment;
      s.blowUpSpeed = flow.blowUpSpeed;
      s.solve.relativeTolerance = flow.tolerance;
      s.levelSetFront = flow.levelSetFront != 0;
      s.levelSetImplicitUpdate = flow.levelSetFront == 2;
      s.carryCouplingVelocity = flow.carryCouplingVelocity != 0;
      s.levelSetRedistancing = flow.levelSetRedistancing == 1   ? solvers::LevelSetRedistancing::FastMarching
                               : flow.levelSetRedistancing == 2 ? solvers::LevelSetRedistancing::None
                                                                : solvers::LevelSetRedistancing::ToMesh;
      s.levelSetKeep = flow.levelSetKeep;
      s.particleLevelSet = flow.particleLevelSet != 0;
      s.particleSettings.reseedEvery = flow.particleReseedEvery;

      const Eigen::Vector2d centroidBefore = solvers::measureFront(state.front).centroid;
      const solvers::TwoPhaseStepReport r = solvers::advanceTwoPhase(state, s, ctx.dt);

      flow.u.assign(state.u.data(), state.u.data() + state.u.size());
      flow.frontPoints.clear();
      for (const auto& x : state.front.points) flow.frontPoints.insert(flow.frontPoints.end(), {x.x(), x.y()});
      flow.frontElements.clear();
      for (const auto& e : state.front.elements) flow.frontElements.insert(flow.frontElements.end(), {e[0], e[1]});
      flow.pInside = state.pInside;
      flow.pOutside = state.pOutside;
      flow.phi = state.phi;
      flow.frontPointVelocity.clear();
      for (const auto& v : state.pointVelocity) flow.frontPointVelocity.insert(flow.frontPointVelocity.end(), {v.x(), v.y()});
      flow.levelSetParticles.clear();
      for (const auto& p : state.levelSetParticles)
        flow.levelSetParticles.insert(flow.levelSetParticles.end(), {p.x.x(), p.x.y(), p.radius, static_cast<double>(p.sign)});

      auto& out = ctx.diagnostics;
      out.max("fluid_max_speed", r.maxSpeed);
      out.max("fluid_cfl", r.cfl);
      out.set("capillary_dt", r.capillaryDt);
      out.max("dt_over_capillary_dt", ctx.dt / r.capillaryDt);
      out.set("surface_tension_pressure_jump", r.pressureJump);
      out.set("front_area", r.area);
      out.set("front_area_drift", flow.initialArea != 0 ? r.area / flow.initialArea - 1 : 0.0);
      out.set("front_points", static_cast<double>(state.front.pointCount()));
      // Sec. 6.4.5's measures: the top and bottom of the front on the vertical line through its
      // centroid, the centroid, its velocity over the step, and the circularity 2 sqrt(pi A) / L.
      const solvers::FrontShape shape = solvers::measureFront(state.front);
      out.set("front_top", shape.top);
      out.set("front_bottom", shape.bottom);
      out.set("front_centroid_x", shape.centroid.x());
      out.set("front_centroid_y", shape.centroid.y());
      out.set("front_rise_velocity", (shape.centroid.y() - centroidBefore.y()) / ctx.dt);
      out.set("front_circularity", shape.circularity);
      out.set("front_remesh_changes", static_cast<double>(r.remeshChanges));
      out.set("fluid_solver_iterations", r.solve.iterations);
      out.set("fluid_solver_relative_residual", r.solve.relativeResidual());
      const auto [l1, linf] = solvers::velocityNorms(state.u);
      out.set("fluid_velocity_l1", l1);
      const auto names = splitNames(flow.probeNames);
      for (std::size_t p = 0; p < names.size() && 2 * p + 1 < flow.probePoints.size(); ++p) {
        const Eigen::Vector2d x(flow.probePoints[2 * p], flow.probePoints[2 * p + 1]);
        out.set(names[p] + "_u", solvers::sampleFaceVelocity(state.layout, state.u, 0, x));
        out.set(names[p] + "_v", solvers::sampleFaceVelocity(state.layout, state.u, 1, x));
      }
      (void)linf;
      if (r.blewUp) {
        std::cerr << "surface_tension_flow: " << r.blowUpReason << "\n";
        out.set(std::string("surface_tension_") + (s.implicitSurfaceTension ? "implicit" : "explicit") + "_blew_up",
                std::numeric_limits<double>::quiet_NaN());
      }
    }
  }
}

template class SurfaceTensionFlow<2>;
template class SurfaceTensionFlow<3>;

}  // namespace monolith
