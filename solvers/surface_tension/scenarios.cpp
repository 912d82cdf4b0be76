#include "solvers/surface_tension/scenarios.h"

#include "solvers/surface_tension/front_metrics.h"
#include "solvers/surface_tension/fast_marching.h"
#include "solvers/surface_tension/pressure_jump.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>

namespace monolith::solvers {

namespace {
// Distance from (x0, y0) to the curve y = sin x: the vertical distance bounds it, so the nearest
// point lies within that many units in x; sample, then Newton on the derivative of the squared distance.
double distanceToSine(double x0, double y0) {
  const double bound = std::abs(y0 - std::sin(x0));
  double best = x0, bestValue = bound * bound;
  for (int i = -40; i <= 40; ++i) {
    const double x = x0 + bound * i / 40.0;
    const double value = (x - x0) * (x - x0) + (std::sin(x) - y0) * (std::sin(x) - y0);
    if (value < bestValue) best = x, bestValue = value;
  }
  double x = best;
  for (int it = 0; it < 50; ++it) {
    const double g = (x - x0) + (std::sin(x) - y0) * std::cos(x);
    const double h = 1 + std::cos(x) * std::cos(x) - (std::sin(x) - y0) * std::sin(x);
    const double step = g / h;
    x -= step;
    if (std::abs(step) < 1e-16) break;
  }
  return std::sqrt((x - x0) * (x - x0) + (std::sin(x) - y0) * (std::sin(x) - y0));
}
}  // namespace

SineInterfaceErrors sineInterfaceErrors(int n, CrossingOrder order) {
  const double dx = 4.0 / n;
  const MacLayout<2> layout(Eigen::Vector2i(2 * n, n), dx, Eigen::Vector2d(0, -2));
  std::vector<double> phi(layout.cellCount());
  for (int c = 0; c < layout.cellCount(); ++c) {
    const Eigen::Vector2d x = layout.cellCenter(layout.cellCoord(c));
    const double vertical = x.y() - std::sin(x.x());
    const double distance = std::abs(vertical) < 10 * dx ? distanceToSine(x.x(), x.y()) : std::abs(vertical);
    phi[c] = vertical >= 0 ? -distance : distance;  // the fluid y >= sin x is inside
  }
  const Front2 front = frontFromLevelSet(layout, phi, order);
  const auto kn = curvatureNormals(front);
  const auto incident = pointSegments(front);
  SineInterfaceErrors e;
  for (int k = 0; k < front.pointCount(); ++k) {
    const Eigen::Vector2d x = front.points[k];
    if (x.x() < 8 * dx || x.x() > 8 - 8 * dx) continue;
    if (incident[k][0] < 0 || incident[k][1] < 0) continue;
    const double eg = std::abs(x.y() - std::sin(x.x()));
    const double c = std::cos(x.x());
    const double ek = std::abs(kn[k].norm() - std::abs(std::sin(x.x())) / std::pow(1 + c * c, 1.5));
    e.interfaceMax = std::max(e.interfaceMax, eg);
    e.curvatureMax = std::max(e.curvatureMax, ek);
    e.interfaceMean += eg;
    e.curvatureMean += ek;
    ++e.points;
  }
  if (e.points > 0) e.interfaceMean /= e.points, e.curvatureMean /= e.points;
  return e;
}

namespace {
// Switches a case to the level-set-tracked front: phi the signed distance to `shape` (a finer
// polyline than the front's, where the exact curve is wanted), the mesh rebuilt from phi.
void trackWithLevelSet(TwoPhaseState& state, TwoPhaseSettings& settings, const Front2& shape) {
  settings.levelSetFront = true;
  state.phi = signedDistanceToFront(state.layout, shape);
  state.front = frontFromLevelSet(state.layout, state.phi, CrossingOrder::Fourth);
}
}  // namespace

TwoPhaseSettings staticCircleSettings(bool onePhase, bool implicit) {
  TwoPhaseSettings s;
  s.densityInside = 1e4;
  s.densityOutside = 1e4;
  s.onePhase = onePhase;
  s.viscosity = 1;
  s.sigma = 1;
  s.implicitSurfaceTension = implicit;
  return s;
}

int staticCircleFrontPoints(int n) {
  return 1 << static_cast<int>(std::lround(std::log2(8 * M_PI * 0.25 * n)));
}

namespace {
void applyLevelSetOptions(TwoPhaseSettings& settings, const LevelSetFrontOptions& options) {
  settings.levelSetRedistancing = options.redistancing;
  settings.levelSetKeep = options.keep;
  settings.particleLevelSet = options.particles;
  settings.particleSettings.reseedEvery = options.reseedEvery;
  settings.levelSetNodeSnap = options.nodeSnap;
}
// Steps a static circle until the end or a blow-up (advance returns true), then takes the
// parasitic-current norms over all faces.
template <class State, class Advance>
StaticCircleResult stepStaticCircle(State& state, int steps, Advance advance) {
  StaticCircleResult r;
  for (int i = 0; i < steps && r.stable; ++i) r.stable = !advance(state);
  const auto [l1, linf] = velocityNorms(state.u);
  r.l1 = l1;
  r.linf = linf;
  r.steps = state.step;
  return r;
}
}  // namespace

StaticCircleResult runStaticCircle(int n, bool onePhase, bool implicit, double endTime, bool levelSet, int points,
                                   bool remesh, double densityOutside, const LevelSetFrontOptions& levelSetOptions,
                                   const StaticCircleObserver& observer) {
  const double dx = 1.0 / n, dt = 0.2 * dx;
  if (points <= 0) points = staticCircleFrontPoints(n);
  TwoPhaseState state = makeTwoPhaseState(MacLayout<2>(Eigen::Vector2i(n, n), dx),
                                          perturbedCircle(Eigen::Vector2d(0.5, 0.5), 0.25, 0, 0, points));
  TwoPhaseSettings settings = staticCircleSettings(onePhase, implicit);
  settings.remesh = remesh;
  settings.densityOutside = densityOutside;
  if (levelSet) {
    settings.levelSetFront = true;
    state.phi.resize(state.layout.cellCount());
    for (int c = 0; c < state.layout.cellCount(); ++c)
      state.phi[c] = (state.layout.cellCenter(state.layout.cellCoord(c)) - Eigen::Vector2d(0.5, 0.5)).norm() - 0.25;
    state.front = frontFromLevelSet(state.layout, state.phi, CrossingOrder::Fourth);
    applyLevelSetOptions(settings, levelSetOptions);
  }
  const std::vector<double> exactPhi = state.phi;
  TwoPhaseStepReport last;
  StaticCircleResult r = stepStaticCircle(state, static_cast<int>(std::lround(endTime / dt)), [&](TwoPhaseState& s) {
    last = advanceTwoPhase(s, settings, dt);
    if (levelSet && levelSetOptions.frozen) s.phi = exactPhi;
    if (observer) observer(s, last);
    return last.blewUp;
  });
  r.pressureJump = last.pressureJump;
  r.lastIterations = last.solve.iterations;
  return r;
}

namespace {
// |u - u_analytic| on every face whose centre lies inside the front, with the face's polar position
// about the drop's centre (angle in radians) and its distance to the front. u_analytic is the
// linear mode-2 field -eps omega rhat (r / rhat) sin(omega t) (cos(-theta), sin(-theta)) (Sec. 6.4.3).
struct FaceError {
  double error = 0, radius = 0, angle = 0, distance = 0;
  int axis = 0;
};
std::vector<FaceError> faceErrors(const TwoPhaseState& state, double epsilon, double omega, double rhat) {
  std::vector<FaceError> out;
  for (int f = 0; f < state.layout.totalFaces(); ++f) {
    const auto [axis, idx] = state.layout.faceCoord(f);
    const Eigen::Vector2d x = state.layout.faceCenter(axis, idx);
    if (!insideFront(state.front, x)) continue;
    const Eigen::Vector2d rel = x - Eigen::Vector2d(0.5, 0.5);
    FaceError e;
    e.axis = axis;
    e.radius = rel.norm();
    e.angle = std::atan2(rel.y(), rel.x());
    const double a = -epsilon * omega * rhat * (e.radius / rhat) * std::sin(omega * state.time);
    const double exact = axis == 0 ? a * std::cos(-e.angle) : a * std::sin(-e.angle);
    e.error = std::abs(state.u[f] - exact);
    e.distance = std::numeric_limits<double>::infinity();
    for (const auto& s : state.front.elements) {
      const Eigen::Vector2d a0 = state.front.points[s[0]], d = state.front.points[s[1]] - a0;
      const double t = std::clamp((x - a0).dot(d) / d.squaredNorm(), 0.0, 1.0);
      e.distance = std::min(e.distance, (a0 + t * d - x).norm());
    }
    out.push_back(e);
  }
  return out;
}
}  // namespace

OscillatingCircleResult runOscillatingCircle(int n, double epsilon, double endTime, int points, bool remesh,
                                             double dtPerDx, bool carryCouplingVelocity, TwoPhaseAdvection advection) {
  const double dx = 1.0 / n, dt = dtPerDx * dx, rhat = 1.0 / 3, omega = 2.0;
  if (points <= 0) points = static_cast<int>(std::lround(2 * M_PI * rhat / dx));
  TwoPhaseState state = makeTwoPhaseState(MacLayout<2>(Eigen::Vector2i(n, n), dx),
                                          perturbedCircle(Eigen::Vector2d(0.5, 0.5), rhat, epsilon, 2, points));
  TwoPhaseSettings settings;
  settings.densityInside = 27;
  settings.onePhase = true;
  settings.sigma = 2.0 / 3;
  settings.blowUpSpeed = 10;
  settings.remesh = remesh;
  settings.carryCouplingVelocity = carryCouplingVelocity;
  settings.advection = advection;
  OscillatingCircleResult r;
  r.points = points;
  const Eigen::Vector2d probe(0.75, 0.5);
  double previousTime = 0, previousU = 0;
  int crossings = 0;
  bool halfDone = false;
  std::optional<TwoPhaseState> atHalf;  // the state at t = 0.5, for the error with the run's own frequency
  while (state.time < endTime - 1e-12) {
    const TwoPhaseStepReport report = advanceTwoPhase(state, settings, dt);
    if (report.blewUp) {
      r.stable = false;
      break;
    }
    const double u = sampleFaceVelocity(state.layout, state.u, 0, probe);
    if (!halfDone && state.time >= 0.5 - 1e-12) {
      halfDone = true;
      // Linear interpolation to t = 0.5 between the last two steps.
      const double w = (0.5 - previousTime) / (state.time - previousTime);
      r.probeAtHalf = previousU + w * (u - previousU);
      const double scale = epsilon * omega * rhat * std::abs(std::sin(omega * state.time));
      atHalf = state;
      for (const FaceError& e : faceErrors(state, epsilon, omega, rhat)) {
        if (e.distance >= 2 * dx) r.interiorRelativeErrorAtHalf = std::max(r.interiorRelativeErrorAtHalf, e.error / scale);
        if (e.error / scale > r.relativeErrorAtHalf) {
          r.relativeErrorAtHalf = e.error / scale;
          r.worstRadius = e.radius / rhat;
          r.worstAngle = e.angle * 180 / M_PI;
          r.worstDistance = e.distance / dx;
          r.worstAxis = e.axis;
        }
      }
      const double probeExact = -epsilon * omega * (probe.x() - 0.5) * std::sin(omega * state.time);
      r.probeRelativeErrorAtHalf = std::abs(u - probeExact) / scale;
    }
    if (state.step > 1 && (previousU < 0) != (u < 0)) {
      ++crossings;
      if (crossings == 2 && r.period == 0) r.period = previousTime + (state.time - previousTime) * previousU / (previousU - u);
    }
    previousTime = state.time;
    previousU = u;
  }
  r.steps = state.step;
  if (r.period > 0 && atHalf) {
    // The analytic field with the run's own frequency 2 pi / T in amplitude and phase.
    const double own = 2 * M_PI / r.period;
    const double scale = epsilon * own * rhat * std::abs(std::sin(own * atHalf->time));
    for (const FaceError& e : faceErrors(*atHalf, epsilon, own, rhat)) {
      r.ownFrequencyRelativeErrorAtHalf = std::max(r.ownFrequencyRelativeErrorAtHalf, e.error / scale);
      if (e.distance >= 2 * dx)
        r.ownFrequencyInteriorRelativeErrorAtHalf = std::max(r.ownFrequencyInteriorRelativeErrorAtHalf, e.error / scale);
    }
  }
  return r;
}

RisingBubbleStability runRisingBubbleStability(int n, double dt, bool implicit, int steps, TwoPhaseAdvection advection,
                                               bool levelSet, double advectionCfl, const LevelSetFrontOptions& levelSetOptions) {
  const double dx = 1.0 / n;
  const int points = static_cast<int>(std::lround(2 * M_PI * 0.2 / dx));
  TwoPhaseState state = makeTwoPhaseState(MacLayout<2>(Eigen::Vector2i(n, 2 * n), dx),
                                          perturbedCircle(Eigen::Vector2d(0.5, 0.5), 0.2, 0, 0, points));
  TwoPhaseSettings settings;
  settings.densityInside = 1e3;
  settings.densityOutside = 1e4;
  settings.viscosity = 1;
  settings.sigma = 0.5;
  settings.gravity = Eigen::Vector2d(0, -8e-4);
  settings.implicitSurfaceTension = implicit;
  settings.blowUpSpeed = 0.1;
  settings.solve.relativeTolerance = 1e-10;
  settings.advection = advection;
  settings.advectionCfl = advectionCfl;
  if (levelSet) {
    trackWithLevelSet(state, settings, perturbedCircle(Eigen::Vector2d(0.5, 0.5), 0.2, 0, 0, 16 * points));
    applyLevelSetOptions(settings, levelSetOptions);
  }
  const double area0 = enclosedArea(state.front);
  RisingBubbleStability r;
  for (int i = 0; i < steps; ++i) {
    const TwoPhaseStepReport report = advanceTwoPhase(state, settings, dt);
    r.maxSpeed = std::max(r.maxSpeed, report.maxSpeed);
    r.capillaryDt = report.capillaryDt;
    r.areaChange = report.area / area0 - 1;
    if (report.blewUp) {
      r.stable = false;
      r.reason = report.blowUpReason;
      break;
    }
  }
  r.steps = state.step;
  return r;
}

RisingBubbleRun runRisingBubble(int n, double endTime, double sampleEvery, double dtPerDx, TwoPhaseAdvection advection,
                                bool levelSet) {
  const double dx = 0.02 / n, radius = 1.0 / 300;
  const int points = static_cast<int>(std::lround(2 * M_PI * radius / dx));
  const Eigen::Vector2d centre(0, 0);
  TwoPhaseState state = makeTwoPhaseState(MacLayout<2>(Eigen::Vector2i(n, 3 * n / 2), dx, Eigen::Vector2d(-0.01, -0.01)),
                                          perturbedCircle(centre, radius, 0, 0, points));
  TwoPhaseSettings settings;
  settings.densityInside = 1.226;
  settings.densityOutside = 1000;
  settings.viscosity = 1.78e-5;
  settings.sigma = 0.0728;
  settings.gravity = Eigen::Vector2d(0, -9.8);
  settings.advection = advection;
  settings.blowUpSpeed = 5.0;
  settings.solve.relativeTolerance = 1e-10;
  if (levelSet) trackWithLevelSet(state, settings, perturbedCircle(centre, radius, 0, 0, 16 * points));
  RisingBubbleRun run;
  run.dt = dtPerDx * dx;
  const double area0 = enclosedArea(state.front);
  FrontShape shape = measureFront(state.front);
  auto sample = [&](double riseVelocity) {
    RisingBubbleSample s;
    s.time = state.time;
    s.top = shape.top;
    s.bottom = shape.bottom;
    s.centroidY = shape.centroid.y();
    s.riseVelocity = riseVelocity;
    s.circularity = shape.circularity;
    s.areaDrift = shape.area / area0 - 1;
    s.front = state.front;
    run.samples.push_back(s);
  };
  sample(0);
  double nextSample = sampleEvery;
  while (state.time < endTime - 1e-12) {
    const double previousY = shape.centroid.y(), stepDt = std::min(run.dt, endTime - state.time);
    const TwoPhaseStepReport report = advanceTwoPhase(state, settings, stepDt);
    run.maxSpeed = std::max(run.maxSpeed, report.maxSpeed);
    run.capillaryDt = report.capillaryDt;
    if (report.blewUp) {
      run.stable = false;
      run.reason = report.blowUpReason;
      break;
    }
    shape = measureFront(state.front);
    if (state.time >= nextSample - 1e-9 * sampleEvery) {
      sample((shape.centroid.y() - previousY) / stepDt);
      nextSample += sampleEvery;
    }
  }
  run.steps = state.step;
  return run;
}

double stabilityCapillaryDt(int n) {
  const double dx = 0.04 / n;
  return std::sqrt(1000 * dx * dx * dx / (4 * M_PI * 0.0728));
}

namespace {
Front2 stabilityShape(int n, bool ellipse, int refine) {
  const double dx = 0.04 / n;
  const Eigen::Vector2d centre(0.02, 0.02);
  const int points = refine * static_cast<int>(std::lround(2 * M_PI * 0.01 / dx));
  if (!ellipse) return perturbedCircle(centre, 0.01, 0, 0, points);
  std::vector<Eigen::Vector2d> x;
  for (int k = 0; k < points; ++k) {
    const double theta = (k + 0.5) * 2 * M_PI / points;
    x.push_back(centre + Eigen::Vector2d(0.011 * std::cos(theta), 0.009 * std::sin(theta)));
  }
  return closedPolyline(x);
}

// Steps the case until `steps` steps are done or it fails: the guard fired, or the area drifted
// by more than 20 %.
template <class State, class Advance>
StabilityCase stepStabilityCase(int n, int steps, State& state, double area0, Advance advance) {
  StabilityCase r;
  r.capillaryDt = stabilityCapillaryDt(n);
  for (int i = 0; i < steps; ++i) {
    const auto report = advance(state);
    r.maxSpeed = std::max(r.maxSpeed, report.maxSpeed);
    if (report.blewUp || std::abs(report.area / area0 - 1) > 0.2) {
      r.stable = false;
      break;
    }
  }
  r.steps = state.step;
  return r;
}
}  // namespace

StabilityCase runPressureJumpStabilityCase(int n, double dt, bool ellipse, int steps) {
  const double dx = 0.04 / n;
  PressureJumpState state;
  state.layout = MacLayout<2>(Eigen::Vector2i(n, n), dx);
  state.u = Eigen::VectorXd::Zero(state.layout.totalFaces());
  state.phi = signedDistanceToFront(state.layout, stabilityShape(n, ellipse, 16), 6);
  PressureJumpSettings settings;
  settings.density = 1000;
  settings.sigma = 0.0728;
  settings.blowUpSpeed = 1.0;
  const double area0 = enclosedArea(frontFromLevelSet(state.layout, state.phi, CrossingOrder::Fourth));
  return stepStabilityCase(n, steps, state, area0, [&](PressureJumpState& s) { return advancePressureJump(s, settings, dt); });
}

StaticCircleResult runPressureJumpStaticCircle(int n, double endTime, double keep) {
  const double dx = 1.0 / n, dt = 0.2 * dx;
  PressureJumpState state;
  state.layout = MacLayout<2>(Eigen::Vector2i(n, n), dx);
  state.u = Eigen::VectorXd::Zero(state.layout.totalFaces());
  state.phi.resize(state.layout.cellCount());
  for (int c = 0; c < state.layout.cellCount(); ++c)
    state.phi[c] = (state.layout.cellCenter(state.layout.cellCoord(c)) - Eigen::Vector2d(0.5, 0.5)).norm() - 0.25;
  PressureJumpSettings settings;
  settings.density = 1e4;
  settings.sigma = 1;
  settings.keep = keep;
  return stepStaticCircle(state, static_cast<int>(std::lround(endTime / dt)),
                          [&](PressureJumpState& s) { return advancePressureJump(s, settings, dt).blewUp; });
}

StabilityCase runStabilityCase(int n, double dt, bool implicit, bool ellipse, int steps, bool levelSet,
                               bool levelSetImplicitUpdate) {
  const double dx = 0.04 / n;
  TwoPhaseState state = makeTwoPhaseState(MacLayout<2>(Eigen::Vector2i(n, n), dx), stabilityShape(n, ellipse, 1));
  TwoPhaseSettings settings;
  settings.densityInside = 1000;
  settings.onePhase = true;
  settings.sigma = 0.0728;
  settings.implicitSurfaceTension = implicit;
  settings.blowUpSpeed = 1.0;
  settings.solve.relativeTolerance = 1e-10;
  if (levelSet) {
    settings.levelSetImplicitUpdate = levelSetImplicitUpdate;
    trackWithLevelSet(state, settings, Front2(state.front));
  }
  return stepStabilityCase(n, steps, state, enclosedArea(state.front),
                           [&](TwoPhaseState& s) { return advanceTwoPhase(s, settings, dt); });
}

VortexDeformationResult runVortexDeformation(int n, double period, bool particles, int reseedEvery, bool reverses) {
  const double dx = 1.0 / n;
  const MacLayout<2> layout(Eigen::Vector2i(n, n), dx);
  const Eigen::Vector2d centre(0.5, 0.75);
  const double radius = 0.15;
  std::vector<double> phi(layout.cellCount());
  for (int c = 0; c < layout.cellCount(); ++c) phi[c] = (layout.cellCenter(layout.cellCoord(c)) - centre).norm() - radius;
  ParticleLevelSetSettings settings;
  settings.reseedEvery = reseedEvery;
  std::vector<LevelSetParticle> markers;
  if (particles) markers = seedParticles(layout, phi, settings);
  VortexDeformationResult result;
  result.particles = static_cast<int>(markers.size());
  // No sliver merging: the stretched spiral's under-resolved tail can leave marching-squares segments
  // that do not chain, and the area (a sum over segments) does not need them to.
  auto front = [&] { return frontFromLevelSet(layout, phi, CrossingOrder::Fourth, 0.0); };
  result.fronts.push_back(front());
  result.initialArea = enclosedArea(result.fronts.back());
  const int steps = static_cast<int>(std::ceil(period / dx - 1e-9));
  const double dt = period / steps;
  Eigen::VectorXd u(layout.totalFaces());
  for (int step = 0; step < steps; ++step) {
    const double time = (step + 0.5) * dt, scale = reverses ? std::cos(M_PI * time / period) : 1.0;
    for (int f = 0; f < layout.totalFaces(); ++f) {
      const auto [axis, coord] = layout.faceCoord(f);
      const Eigen::Vector2d x = layout.faceCenter(axis, coord);
      const double sx = std::sin(M_PI * x.x()), sy = std::sin(M_PI * x.y());
      u[f] = scale * (axis == 0 ? -sx * sx * std::sin(2 * M_PI * x.y()) : sy * sy * std::sin(2 * M_PI * x.x()));
    }
    if (particles) {
      result.escapedTotal += particleLevelSetStep(layout, u, dt, phi, markers, settings);
      if (settings.reseedEvery > 0 && (step + 1) % settings.reseedEvery == 0) {
        const ReseedReport r = reseedParticles(layout, phi, markers, static_cast<std::uint64_t>(step + 1), settings);
        result.reseeded.added += r.added;
        result.reseeded.removedOutsideBand += r.removedOutsideBand;
        result.reseeded.removedEscaped += r.removedEscaped;
        result.reseeded.removedCrowded += r.removedCrowded;
      }
    } else {
      phi = advectCellField(layout, phi, u, dt);
      fastMarchingRedistance(layout, phi, settings.redistanceBand);
    }
    if (step + 1 == steps / 2) {
      result.fronts.push_back(front());
      result.halfArea = enclosedArea(result.fronts.back());
      result.halfParticles = static_cast<int>(markers.size());
      if (particles) result.halfBounds = particleCountBounds(layout, phi, markers, settings);
    }
  }
  result.finalParticles = static_cast<int>(markers.size());
  if (particles) result.finalBounds = particleCountBounds(layout, phi, markers, settings);
  result.fronts.push_back(front());
  result.finalArea = enclosedArea(result.fronts.back());
  result.areaError = (result.finalArea - result.initialArea) / result.initialArea;
  result.halfAreaError = (result.halfArea - result.initialArea) / result.initialArea;
  for (const auto& x : result.fronts.back().points)
    result.maxShapeError = std::max(result.maxShapeError, std::abs((x - centre).norm() - radius));
  result.steps = steps;
  return result;
}

}  // namespace monolith::solvers
