// Surface tension on a Lagrangian front (thesis Ch. 6): the experiments of Sec. 6.4 with the
// solvers of solvers/surface_tension, printed with wall time and error beside the thesis's tables.
//   bench_surface_tension sine [N...]                 Table 6.1
//   bench_surface_tension static one|two|one_ls|two_ls [N...]   Tables 6.2 / 6.3 (t = 5, dt = 0.2 dx)
//   bench_surface_tension oscillating [N...]          Table 6.4 refinement test (period, u at t = 0.5)
//   bench_surface_tension epsilon N                   Table 6.4 epsilon test
//   bench_surface_tension rising_stability [N]        Sec. 6.4.4 (implicit and explicit, dt = 3 and 7 s)
//   bench_surface_tension stability_map               Fig. 6.6-style sweep
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

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
    const bool one = argc > 2 && (std::string(argv[2]) == "one" || std::string(argv[2]) == "one_ls");
    const bool ls = argc > 2 && std::string(argv[2]).find("_ls") != std::string::npos;
    std::printf("static circle, %s phase, %s, implicit, t = 5, dt = 0.2 dx\n"
                "| 1/dx | L1(u) | Linf(u) | pressure jump | jump error | steps | CG its (last) | wall s |\n|---|---|---|---|---|---|---|---|\n",
                one ? "one" : "two", ls ? "level-set front" : "front tracking");
    for (int n : sizes(argc, argv, 3, {20, 40, 80})) {
      const auto start = std::chrono::steady_clock::now();
      const StaticCircleResult r = runStaticCircle(n, one, true, 5.0, ls);
      std::printf("| %d | %.3e | %.3e | %.5f | %.2e | %d | %d | %.1f |\n", n, r.l1, r.linf, r.pressureJump,
                  std::abs(r.pressureJump - 4.0) / 4.0, r.steps, r.lastIterations, seconds(start));
      std::fflush(stdout);
    }
  } else if (mode == "oscillating" || mode == "epsilon") {
    const bool eps = mode == "epsilon";
    std::printf("oscillating circle, front tracking, implicit\n| N | epsilon | period T | T/pi - 1 | u(0.75,0.5) at t=0.5 | rel. Linf err at t=0.5 | steps | wall s |\n|---|---|---|---|---|---|---|---|\n");
    const std::vector<int> ns = eps ? sizes(argc, argv, 2, {50}) : sizes(argc, argv, 2, {50, 100});
    for (int n : ns)
      for (double epsilon : eps ? std::vector<double>{0.05, 0.025, 0.0125} : std::vector<double>{0.05}) {
        const auto start = std::chrono::steady_clock::now();
        const OscillatingCircleResult r = runOscillatingCircle(n, epsilon, 1.2 * M_PI);
        std::printf("| %d | %g | %.4f | %+.2f %% | %.4e | %.3e | %d | %.1f |\n", n, epsilon, r.period, 100 * (r.period / M_PI - 1),
                    r.probeAtHalf, r.relativeErrorAtHalf, r.steps, seconds(start));
        std::fflush(stdout);
      }
  } else if (mode == "rising_stability") {
    const int n = argc > 2 ? std::atoi(argv[2]) : 80;
    std::printf("rising bubble stability (Sec. 6.4.4: %dx%d, rho 1e4/1e3, mu 1, sigma 0.5, g -8e-4), to t = 90 s, semi-Lagrangian\n"
                "| dt | variant | stable | steps | max speed | capillary dt | dt / capillary | area drift | blow-up | wall s |\n|---|---|---|---|---|---|---|---|---|---|\n",
                n, 2 * n);
    for (double dt : std::vector<double>{3.0, 7.0}) {
      for (bool implicit : {true, false}) {
        const auto start = std::chrono::steady_clock::now();
        const RisingBubbleStability r = runRisingBubbleStability(n, dt, implicit, static_cast<int>(std::lround(90 / dt)));
        std::printf("| %g | %s | %s | %d | %.3e | %.4f | %.1f | %.3f | %s | %.1f |\n", dt, implicit ? "implicit" : "explicit",
                    r.stable ? "yes" : "no", r.steps, r.maxSpeed, r.capillaryDt, dt / r.capillaryDt, r.areaChange, r.reason.c_str(),
                    seconds(start));
        std::fflush(stdout);
      }
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
  } else {
    std::fprintf(stderr, "unknown mode %s\n", mode.c_str());
    return 2;
  }
  return 0;
}
