// Surface tension on a Lagrangian front (thesis Ch. 6): the experiments of Sec. 6.4 with the
// solvers of solvers/surface_tension, printed with wall time and error beside the thesis's tables.
//   bench_surface_tension sine [N...]                 Table 6.1
//   bench_surface_tension static one|two|one_ls|two_ls|pj [N...] [t_end=T]   Tables 6.2 / 6.3 (t = 5, dt = 0.2 dx)
//   bench_surface_tension oscillating [N...]          Table 6.4 refinement test (period, u at t = 0.5)
//   bench_surface_tension epsilon N [eps=E...]        Table 6.4 epsilon test
//   bench_surface_tension rising_stability [N]        Sec. 6.4.4 (implicit and explicit, dt = 3 and 7 s)
//   bench_surface_tension stability_map               Fig. 6.6-style sweep
//   bench_surface_tension vortex [T] [N...] [reseed=K...]  particle level set (reseeded every K steps) against the plain one
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "solvers/surface_tension/front_metrics.h"
#include "solvers/surface_tension/scenarios.h"

using namespace monolith::solvers;

namespace {
double seconds(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}
std::vector<int> sizes(int argc, char** argv, int first, std::vector<int> fallback) {
  std::vector<int> out;
  for (int i = first; i < argc; ++i) out.push_back(std::atoi(argv[i]));
  return out.empty() ? fallback : out;
}
}  // namespace

int main(int argc, char** argv) {
  const std::string mode = argc > 1 ? argv[1] : "static";
  if (mode == "sine") {
    for (CrossingOrder order : {CrossingOrder::Third, CrossingOrder::Fourth}) {
      std::printf("%s order interface\n| N | Linf(eG) | L1(eG) | Linf(ek) | L1(ek) | points | wall s |\n|---|---|---|---|---|---|---|\n",
                  order == CrossingOrder::Third ? "Third" : "Fourth");
      for (int n : sizes(argc, argv, 2, {40, 80, 160, 320})) {
        const auto start = std::chrono::steady_clock::now();
        const SineInterfaceErrors e = sineInterfaceErrors(n, order);
        std::printf("| %d | %.3e | %.3e | %.3e | %.3e | %d | %.2f |\n", n, e.interfaceMax, e.interfaceMean, e.curvatureMax,
                    e.curvatureMean, e.points, seconds(start));
      }
    }
  } else if (mode == "static") {
    // Options among the sizes: points=P (front points; default the original driver's 2^k at about
    // dx / 4; one_per_dx: one point per dx of arc), remesh, rho_out=R, t_end=T (default the thesis's 5),
    // trace=K (every K steps, and at every step whose front has a new point count: the currents, where
    // the largest is, the front's area error, centroid and points), snap=S (level sets: crossings
    // within S dx of a node put on it; default 1e-4, 0 off).
    const bool one = argc > 2 && (std::string(argv[2]) == "one" || std::string(argv[2]) == "one_ls");
    const bool ls = argc > 2 && std::string(argv[2]).find("_ls") != std::string::npos;
    int points = 0;
    bool remesh = false;
    double rhoOut = 1e4, endTime = 5.0;
    LevelSetFrontOptions lsOptions;
    bool keepGiven = false;  // the pressure jump scheme keeps 2 cells unless told
    int traceEvery = 0;      // trace=K: every K steps, the currents and the front's area, centroid, points
    std::vector<int> ns;
    for (int i = 3; i < argc; ++i) {
      const std::string a = argv[i];
      if (a.rfind("points=", 0) == 0) points = std::atoi(a.c_str() + 7);
      else if (a == "one_per_dx") points = -1;
      else if (a == "remesh") remesh = true;
      else if (a.rfind("rho_out=", 0) == 0) rhoOut = std::atof(a.c_str() + 8);
      else if (a.rfind("t_end=", 0) == 0) endTime = std::atof(a.c_str() + 6);
      else if (a == "redistance=fmm") lsOptions.redistancing = LevelSetRedistancing::FastMarching;
      else if (a == "redistance=none") lsOptions.redistancing = LevelSetRedistancing::None;
      else if (a.rfind("keep=", 0) == 0) lsOptions.keep = std::atof(a.c_str() + 5), keepGiven = true;
      else if (a == "particles") lsOptions.particles = true;
      else if (a == "frozen") lsOptions.frozen = true;
      else if (a.rfind("snap=", 0) == 0) lsOptions.nodeSnap = std::atof(a.c_str() + 5);
      else if (a.rfind("trace=", 0) == 0) traceEvery = std::atoi(a.c_str() + 6);
      else ns.push_back(std::atoi(a.c_str()));
    }
    if (ns.empty()) ns = {20, 40, 80};
    if (ls)
      std::printf("level set: redistancing %s, keep %g dx, node snap %g dx%s%s\n",
                  lsOptions.redistancing == LevelSetRedistancing::ToMesh       ? "to the mesh"
                  : lsOptions.redistancing == LevelSetRedistancing::FastMarching ? "fast marching"
                                                                                 : "none",
                  lsOptions.keep, lsOptions.nodeSnap, lsOptions.particles ? ", particle level set" : "", lsOptions.frozen ? ", frozen" : "");
    std::printf("static circle, %s phase, %s, implicit, t = %g, dt = 0.2 dx, front points %s%s, rho_out %g\n"
                "| 1/dx | L1(u) | Linf(u) | pressure jump | jump error | steps | CG its (last) | wall s |\n|---|---|---|---|---|---|---|---|\n",
                one ? "one" : "two", ls ? "level-set front" : "front tracking", endTime,
                points == 0 ? "2^k at about dx/4" : points < 0 ? "one per dx" : std::to_string(points).c_str(), remesh ? ", remeshed" : "", rhoOut);
    for (int n : ns) {
      const auto start = std::chrono::steady_clock::now();
      if (std::string(argv[2]) == "pj") {  // the pressure jump scheme (one phase, inviscid, explicit)
        const StaticCircleResult r = runPressureJumpStaticCircle(n, endTime, keepGiven ? lsOptions.keep : 2.0);
        std::printf("| %d | %.3e | %.3e | pressure jump scheme | %s | %d | | %.1f |\n", n, r.l1, r.linf, r.stable ? "stable" : "blew up",
                    r.steps, seconds(start));
        std::fflush(stdout);
        continue;
      }
      const int p = points >= 0 ? points : static_cast<int>(std::lround(2 * M_PI * 0.25 * n));
      StaticCircleObserver trace;
      int lastPoints = -1;
      if (traceEvery > 0)
        trace = [&](const TwoPhaseState& state, const TwoPhaseStepReport& report) {
          const bool changed = lastPoints >= 0 && state.front.pointCount() != lastPoints;  // the mesh's topology moved
          lastPoints = state.front.pointCount();
          if (state.step % traceEvery != 0 && !changed) return;
          const auto [l1, linf] = velocityNorms(state.u);
          const FrontShape shape = measureFront(state.front);
          Eigen::Index worst = 0;
          state.u.cwiseAbs().maxCoeff(&worst);
          const auto [axis, face] = state.layout.faceCoord(static_cast<int>(worst));
          const Eigen::Vector2d at = state.layout.faceCenter(axis, face);
          std::printf("  t %.3f  L1 %.3e  Linf %.3e at (%.4f, %.4f) axis %d  area-pi r^2 %+.3e  centroid %+.3e %+.3e  points %d  cut cells %d  CG %d\n",
                      state.time, l1, linf, at.x(), at.y(), axis, shape.area - M_PI * 0.0625, shape.centroid.x() - 0.5,
                      shape.centroid.y() - 0.5, state.front.pointCount(), report.cutCells, report.solve.iterations);
          std::fflush(stdout);
        };
      const StaticCircleResult r = runStaticCircle(n, one, true, endTime, ls, p, remesh, rhoOut, lsOptions, trace);
      std::printf("| %d | %.3e | %.3e | %.5f | %.2e | %d | %d | %.1f |\n", n, r.l1, r.linf, r.pressureJump,
                  std::abs(r.pressureJump - 4.0) / 4.0, r.steps, r.lastIterations, seconds(start));
      std::fflush(stdout);
    }
  } else if (mode == "oscillating" || mode == "epsilon") {
    // Options among the sizes: points=P (front points; default one per dx of arc; driver: the
    // original driver's 2^k at about dx / 4 as in the static circle, with r = 1/3), no_remesh,
    // dt_per_dx=S (dt = S dx; default 1/4), carry (the coupling faces' u* carried on the front),
    // eps=E (repeatable; default 0.05, or the epsilon table's 0.05, 0.025, 0.0125), t_end=T (default
    // 1.2 pi, past the second zero crossing; with T < 3.3 there is no period, only the errors at t = 0.5),
    // advection=none|eno (default semi-Lagrangian).
    // Columns: the relative error as defined (scale eps omega r |sin omega t|), the same max error
    // on the scale eps omega |sin omega t| (without r; see docs/benchmarks_surface_tension.md), and
    // the probe's relative error.
    const bool eps = mode == "epsilon";
    int points = 0;
    bool remesh = true;
    double dtPerDx = 0.25, endTime = 1.2 * M_PI;
    bool carry = false;
    TwoPhaseAdvection advection = TwoPhaseAdvection::SemiLagrangian;
    std::vector<int> ns;
    std::vector<double> epsilons;
    for (int i = 2; i < argc; ++i) {
      const std::string a = argv[i];
      if (a.rfind("dt_per_dx=", 0) == 0) dtPerDx = std::atof(a.c_str() + 10);
      else if (a == "points=driver") points = -1;
      else if (a.rfind("points=", 0) == 0) points = std::atoi(a.c_str() + 7);
      else if (a == "no_remesh") remesh = false;
      else if (a == "carry") carry = true;
      else if (a.rfind("eps=", 0) == 0) epsilons.push_back(std::atof(a.c_str() + 4));
      else if (a.rfind("t_end=", 0) == 0) endTime = std::atof(a.c_str() + 6);
      else if (a == "advection=none") advection = TwoPhaseAdvection::None;
      else if (a == "advection=eno") advection = TwoPhaseAdvection::EnoRk3;
      else ns.push_back(std::atoi(a.c_str()));
    }
    if (ns.empty()) ns = eps ? std::vector<int>{50} : std::vector<int>{50, 100};
    if (epsilons.empty()) epsilons = eps ? std::vector<double>{0.05, 0.025, 0.0125} : std::vector<double>{0.05};
    std::printf("oscillating circle, front tracking, implicit, dt = %g dx, coupling u* %s, front %s%s\n"
                "| N | epsilon | period T | T/pi - 1 | u(0.75,0.5) at t=0.5 | rel. Linf err at t=0.5 | same, scale without r | probe rel. err | points | steps | wall s |\n"
                "|---|---|---|---|---|---|---|---|---|---|---|\n"
                "  (then: the max error's face: r / rhat, angle, distance to the front in dx, axis; the max over faces >= 2 dx\n"
                "   inside; the max with the analytic field at the run's own frequency 2 pi / T, over all faces and >= 2 dx\n"
                "   inside; all scaled as the rel. Linf, with r; divide by 3 for the thesis's scale)\n",
                dtPerDx, carry ? "carried on the front" : "sampled from the grid", points == 0 ? "one point per dx" : points < 0 ? "2^k points at about dx/4" : std::to_string(points).c_str(),
                remesh ? ", remeshed" : ", not remeshed");
    for (int n : ns)
      for (double epsilon : epsilons) {
        const auto start = std::chrono::steady_clock::now();
        const int p = points >= 0 ? points : 1 << static_cast<int>(std::lround(std::log2(8 * M_PI * n / 3.0)));
        const OscillatingCircleResult r = runOscillatingCircle(n, epsilon, endTime, p, remesh, dtPerDx, carry, advection);
        std::printf("| %d | %g | %.4f | %+.2f %% | %.4e | %.3e | %.3e | %.3e | %d | %d | %.1f |\n", n, epsilon, r.period,
                    100 * (r.period / M_PI - 1), r.probeAtHalf, r.relativeErrorAtHalf, r.relativeErrorAtHalf / 3,
                    r.probeRelativeErrorAtHalf, r.points, r.steps, seconds(start));
        std::printf("  worst at r/rhat %.3f, angle %.1f deg, %.2f dx from the front, axis %d; >= 2 dx inside %.3e; own frequency %.3e, >= 2 dx inside %.3e\n",
                    r.worstRadius, r.worstAngle, r.worstDistance, r.worstAxis, r.interiorRelativeErrorAtHalf,
                    r.ownFrequencyRelativeErrorAtHalf, r.ownFrequencyInteriorRelativeErrorAtHalf);
        std::fflush(stdout);
      }
  } else if (mode == "rising_stability") {
    // rising_stability [N] [sl|eno|eno_sub] [front|ls|ls_fmm|pls] [dt...]: both variants at each dt, to t = 90 s.
    // eno_sub: ENO/RK3 in substeps of CFL <= 0.9.
    const int n = argc > 2 ? std::atoi(argv[2]) : 80;
    const bool eno = argc > 3 && std::string(argv[3]).rfind("eno", 0) == 0;
    const double advectionCfl = argc > 3 && std::string(argv[3]) == "eno_sub" ? 0.9 : 0.0;
    // ls_fmm: fast marching instead of the distance to the mesh; pls: the particle level set with it;
    // plsK: the same, reseeded every K steps.
    std::string tracking = argc > 4 ? argv[4] : "front";
    LevelSetFrontOptions lsOptions;
    if (tracking.rfind("pls", 0) == 0 && tracking.size() > 3) {
      lsOptions.reseedEvery = std::atoi(tracking.c_str() + 3);
      tracking = "pls";
    }
    const bool ls = tracking == "ls" || tracking == "ls_fmm" || tracking == "pls";
    if (tracking != "ls") lsOptions.redistancing = LevelSetRedistancing::FastMarching;
    lsOptions.particles = tracking == "pls";
    std::vector<double> dts;
    for (int i = 5; i < argc; ++i) dts.push_back(std::atof(argv[i]));
    if (dts.empty()) dts = {3.0, 7.0};
    std::printf("rising bubble stability (Sec. 6.4.4: %dx%d, rho 1e4/1e3, mu 1, sigma 0.5, g -8e-4), to t = 90 s, %s, %s\n"
                "| dt | variant | stable | steps | max speed | max CFL | capillary dt | dt / capillary | area drift | blow-up | wall s |\n"
                "|---|---|---|---|---|---|---|---|---|---|---|\n",
                n, 2 * n, eno ? (advectionCfl > 0 ? "ENO/RK3 in substeps of CFL <= 0.9" : "ENO/RK3") : "semi-Lagrangian",
                ls ? (tracking == "pls" ? (lsOptions.reseedEvery > 0 ? "particle level set (fast marching), reseeded"
                                                                      : "particle level set (fast marching)")
                                        : tracking == "ls_fmm" ? "level set (fast marching)" : "level-set front")
                   : "front tracking");
    for (double dt : dts) {
      for (bool implicit : {true, false}) {
        const auto start = std::chrono::steady_clock::now();
        const RisingBubbleStability r =
            runRisingBubbleStability(n, dt, implicit, static_cast<int>(std::lround(90 / dt)),
                                     eno ? TwoPhaseAdvection::EnoRk3 : TwoPhaseAdvection::SemiLagrangian, ls, advectionCfl, lsOptions);
        std::printf("| %g | %s | %s | %d | %.3e | %.2f | %.4f | %.1f | %.3f | %s | %.1f |\n", dt, implicit ? "implicit" : "explicit",
                    r.stable ? "yes" : "no", r.steps, r.maxSpeed, r.maxSpeed * dt * n, r.capillaryDt, dt / r.capillaryDt, r.areaChange,
                    r.reason.c_str(), seconds(start));
        std::fflush(stdout);
      }
    }
  } else if (mode == "rising_bubble") {
    // rising_bubble [sl|eno] [front|ls] [endTime] [N...] [dt_per_dx=S] [fronts=PREFIX]: Sec. 6.4.5,
    // top and bottom of the bubble on the vertical line through its centroid against time at each
    // resolution, then the observed orders at the end time. dt = S dx (default 2 s/m); fronts=PREFIX
    // writes each sample's front to PREFIX_N.csv (time, x, y per point, in order along the front).
    const bool eno = argc > 2 && std::string(argv[2]) == "eno";
    const bool ls = argc > 3 && std::string(argv[3]) == "ls";
    const double endTime = argc > 4 ? std::atof(argv[4]) : 0.05;
    double dtPerDx = 2.0;
    std::string frontsPrefix;
    std::vector<int> ns;
    for (int i = 5; i < argc; ++i) {
      const std::string a = argv[i];
      if (a.rfind("dt_per_dx=", 0) == 0) dtPerDx = std::atof(a.c_str() + 10);
      else if (a.rfind("fronts=", 0) == 0) frontsPrefix = a.substr(7);
      else ns.push_back(std::atoi(a.c_str()));
    }
    if (ns.empty()) ns = {20, 40, 80};
    std::vector<RisingBubbleRun> runs;
    for (int n : ns) {
      const auto start = std::chrono::steady_clock::now();
      runs.push_back(runRisingBubble(n, endTime, endTime / 10, dtPerDx, eno ? TwoPhaseAdvection::EnoRk3 : TwoPhaseAdvection::SemiLagrangian, ls));
      const RisingBubbleRun& r = runs.back();
      if (!frontsPrefix.empty()) {
        FILE* out = std::fopen((frontsPrefix + "_" + std::to_string(n) + ".csv").c_str(), "w");
        if (!out) {
          std::fprintf(stderr, "cannot write %s_%d.csv\n", frontsPrefix.c_str(), n);
          return 1;
        }
        std::fprintf(out, "time,x,y\n");
        for (const auto& s : r.samples)
          for (const auto& e : s.front.elements)
            std::fprintf(out, "%.6f,%.9e,%.9e\n", s.time, s.front.points[e[0]].x(), s.front.points[e[0]].y());
        std::fclose(out);
      }
      std::printf("\n%dx%d, %s, %s, dt %.3g s (%.1f x capillary), %d steps, %s, max speed %.3f m/s, wall %.1f s\n"
                  "| t (s) | top (m) | bottom (m) | centroid y (m) | rise velocity (m/s) | circularity | area drift |\n|---|---|---|---|---|---|---|\n",
                  n, 3 * n / 2, eno ? "ENO/RK3" : "semi-Lagrangian", ls ? "level-set front" : "front tracking", r.dt,
                  r.dt / r.capillaryDt, r.steps, r.stable ? "stable" : r.reason.c_str(), r.maxSpeed, seconds(start));
      for (const auto& s : r.samples)
        std::printf("| %.4f | %.5e | %.5e | %.5e | %.4f | %.4f | %+.2e |\n", s.time, s.top, s.bottom, s.centroidY, s.riseVelocity,
                    s.circularity, s.areaDrift);
      std::fflush(stdout);
    }
    // Observed order from three successive resolutions at the end time: log2 |e(h) - e(h/2)| / |e(h/2) - e(h/4)|.
    for (std::size_t i = 0; i + 2 < runs.size(); ++i) {
      if (runs[i].samples.empty() || runs[i + 1].samples.empty() || runs[i + 2].samples.empty()) continue;
      const auto &a = runs[i].samples.back(), &b = runs[i + 1].samples.back(), &c = runs[i + 2].samples.back();
      std::printf("order at t = %.4f from N = %d, %d, %d: top %.2f, bottom %.2f\n", c.time, ns[i], ns[i + 1], ns[i + 2],
                  std::log2(std::abs(a.top - b.top) / std::abs(b.top - c.top)),
                  std::log2(std::abs(a.bottom - b.bottom) / std::abs(b.bottom - c.bottom)));
    }
  } else if (mode == "stability_csv") {
    // stability_csv circle|ellipse ft_explicit|ft_implicit|ls_explicit|ls_implicit|ls_implicit_update|pressure_jump STEPS N...: one CSV row
    // per (N, dt multiple), for tests/bench/plot_stability_map.py.
    const bool ellipse = argc > 2 && std::string(argv[2]) == "ellipse";
    const std::string scheme = argc > 3 ? argv[3] : "ft_implicit";
    const int steps = argc > 4 ? std::atoi(argv[4]) : 500;
    const bool implicit = scheme.find("implicit") != std::string::npos, ls = scheme.rfind("ls", 0) == 0;
    const bool update = scheme == "ls_implicit_update";
    for (int n : sizes(argc, argv, 5, {16, 32, 64}))
      for (double m : {0.5, 1.0, 2.0, 4.0, 8.0, 16.0, 32.0, 64.0, 128.0}) {
        const auto start = std::chrono::steady_clock::now();
        const StabilityCase r = scheme == "pressure_jump"
                                    ? runPressureJumpStabilityCase(n, m * stabilityCapillaryDt(n), ellipse, steps)
                                    : runStabilityCase(n, m * stabilityCapillaryDt(n), implicit, ellipse, steps, ls, update);
        std::printf("%s,%s,%d,%g,%.6g,%d,%d,%.4g,%.2f\n", ellipse ? "ellipse" : "circle", scheme.c_str(), n, m,
                    m * stabilityCapillaryDt(n), r.stable ? 1 : 0, r.steps, r.maxSpeed, seconds(start));
        std::fflush(stdout);
      }
  } else if (mode == "stability_map") {
    // Figs. 6.6/6.7: o stable for 500 steps, x unstable; rows dt as multiples of the explicit
    // capillary limit at that dx, columns 1/dx.
    const int steps = argc > 2 ? std::atoi(argv[2]) : 500;
    const std::vector<int> ns{16, 32, 64};
    const std::vector<double> multiples{0.5, 1, 2, 4, 8, 16, 32, 64, 128};
    for (bool ellipse : {false, true})
      for (int scheme = 0; scheme < 4; ++scheme) {
        const bool implicit = scheme % 2 == 1, ls = scheme >= 2;
        const auto start = std::chrono::steady_clock::now();
        std::printf("\n%s, %s, %s (%d steps)\n| dt / capillary dt |", ellipse ? "ellipse 0.011 x 0.009" : "circle r = 0.01",
                    ls ? "level set" : "front tracking", implicit ? "implicit" : "explicit", steps);
        for (int n : ns) std::printf(" N=%d |", n);
        std::printf("\n|---|");
        for (std::size_t i = 0; i < ns.size(); ++i) std::printf("---|");
        std::printf("\n");
        for (double m : multiples) {
          std::printf("| %g |", m);
          for (int n : ns) {
            const StabilityCase r = runStabilityCase(n, m * stabilityCapillaryDt(n), implicit, ellipse, steps, ls);
            std::printf(" %s |", r.stable ? "o" : "x");
            std::fflush(stdout);
          }
          std::printf("\n");
        }
        std::printf("(wall %.1f s)\n", seconds(start));
      }
  } else if (mode == "vortex") {
    // vortex [T] [N...] [fronts=PREFIX]: the single-vortex test of the particle level set [47], plain
    // level set (semi-Lagrangian + fast marching) against the particle level set. fronts=PREFIX writes
    // PREFIX_N.csv: scheme, time label (0, half, end), x, y per point of each segment's start.
    // reseed=K adds the particle level set reseeded every K steps; no_reversal keeps the field steady.
    const double period = argc > 2 ? std::atof(argv[2]) : 2.0;
    std::string frontsPrefix;
    std::vector<int> ns, reseeds = {0};
    bool reverses = true;
    for (int i = 3; i < argc; ++i) {
      const std::string a = argv[i];
      if (a == "no_reversal") reverses = false;
      else if (a.rfind("fronts=", 0) == 0) frontsPrefix = a.substr(7);
      else if (a.rfind("reseed=", 0) == 0) reseeds.push_back(std::atoi(a.c_str() + 7));
      else ns.push_back(std::atoi(a.c_str()));
    }
    if (ns.empty()) ns = {32, 64, 128};
    std::printf("single vortex%s, circle r = 0.15 at (0.5, 0.75), T = %g, dt = dx; cells (cell, sign) below half / above twice reseeding's target\n"
                "| N | scheme | area error at T/2 | area error at T | max radius error at T | particles at 0 / T/2 / T | "
                "sparse / crowded of counted at T/2 | at T | escaped (sum over steps) | "
                "reseeding: added, removed outside / escaped / crowded | steps | wall s |\n"
                "|---|---|---|---|---|---|---|---|---|---|---|---|\n",
                reverses ? "" : " without reversal", period);
    for (int n : ns) {
      FILE* out = frontsPrefix.empty() ? nullptr : std::fopen((frontsPrefix + "_" + std::to_string(n) + ".csv").c_str(), "w");
      std::vector<std::pair<bool, int>> schemes = {{false, 0}};
      for (int k : reseeds) schemes.emplace_back(true, k);
      for (const auto& [particles, reseed] : schemes) {
        const auto start = std::chrono::steady_clock::now();
        const VortexDeformationResult r = runVortexDeformation(n, period, particles, reseed, reverses);
        const std::string name = !particles ? "level set"
                                 : reseed > 0 ? "particle level set, reseeded every " + std::to_string(reseed)
                                              : "particle level set";
        std::printf("| %d | %s | %+.3e | %+.3e | %.3e | %d / %d / %d | %d / %d of %d | %d / %d of %d | %d | %d, %d / %d / %d | %d | %.1f |\n", n,
                    name.c_str(), r.halfAreaError, r.areaError, r.maxShapeError, r.particles, r.halfParticles, r.finalParticles,
                    r.halfBounds.sparse, r.halfBounds.crowded, r.halfBounds.counted, r.finalBounds.sparse, r.finalBounds.crowded,
                    r.finalBounds.counted, r.escapedTotal, r.reseeded.added,
                    r.reseeded.removedOutsideBand, r.reseeded.removedEscaped, r.reseeded.removedCrowded, r.steps, seconds(start));
        std::fflush(stdout);
        const char* labels[] = {"0", "half", "end"};
        const std::string label = !particles ? "plain" : reseed > 0 ? "reseeded" + std::to_string(reseed) : "particles";
        if (out)
          for (std::size_t k = 0; k < r.fronts.size(); ++k)
            for (const auto& e : r.fronts[k].elements)
              std::fprintf(out, "%s,%s,%.9g,%.9g,%.9g,%.9g\n", label.c_str(), labels[k], r.fronts[k].points[e[0]].x(),
                           r.fronts[k].points[e[0]].y(), r.fronts[k].points[e[1]].x(), r.fronts[k].points[e[1]].y());
      }
      if (out) std::fclose(out);
    }
  } else {
    std::fprintf(stderr, "unknown mode %s\n", mode.c_str());
    return 2;
  }
  return 0;
}
