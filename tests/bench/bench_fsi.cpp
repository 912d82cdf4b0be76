// Two-way rigid-body/fluid coupling (thesis Ch. 5; docs/benchmarks_fsi.md). Modes:
//   bench_fsi channel [finest=96]   channel_plate (Sec. 5.11.1): steady plate velocity against
//                                   v_s = -2.9944 m/s at 12, 24, 48, ... cells, observed order
//   bench_fsi cylinder [finest=80] [mus=all] [end scale=1] [no_stokes]
//                                   falling_cylinder (Sec. 5.11.2, Table 5.1): terminal velocity
//                                   for each mu at 40x160, 80x320, ... beside the thesis's columns;
//                                   also Stokes flow at mu = 0.1
//   bench_fsi precond [finest=160] [mu=0.1]
//                                   iterations of the coupled solve per step for the four
//                                   preconditioners (none, block_jacobi, block_exact, schur) against
//                                   resolution (falling_cylinder, first 5 steps)
//   bench_fsi sphere [cells=16,24,32]
//                                   falling_sphere (3-D, a circular tube, walls at the surfaces):
//                                   terminal velocity against Stokes' law with the Haberman-Sayre
//                                   wall correction, -0.02881 m/s
//   bench_fsi beam [finest=128] [reference=256]
//                                   beam (Sec. 5.11.5): top-right particle at t = 1 s against the
//                                   reference grid, observed order
//   bench_fsi disk [cells=64]       oscillating_disk (Sec. 5.11.6): energies over time, the
//                                   elastic energy's extrema (the oscillation)
//   bench_fsi vortex [end=120]      vortex_shedding_spring: the spring-mounted cylinder's
//                                   cross-stream amplitude and frequency over the last half
// Every row prints the wall time of its run.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "scenarios/simulation.h"

using namespace monolith;

namespace {

std::string num(double x) {
  char b[40];
  std::snprintf(b, sizeof b, "%.17g", x);
  return b;
}

struct Run {
  double seconds = 0;
  long steps = 0;
  std::map<std::string, double> last;
  double meanIterations = 0, maxIterations = 0;
  double maxEnergyChange = -1e300;
};

template <int d = 2>
Run runScene(const Registry& registry, const std::string& scene, const std::vector<Override>& overrides, long maxSteps = -1,
             std::vector<std::map<std::string, double>>* history = nullptr) {
  const SceneSpec spec = loadScene(std::string(MONOLITH_SOURCE_DIR) + "/scenarios/scenes/" + scene, overrides);
  Simulation<d> sim(spec, registry, 2);
  Run r;
  const auto t0 = std::chrono::steady_clock::now();
  double iterations = 0;
  while (!sim.finished() && (maxSteps < 0 || r.steps < maxSteps)) {
    r.last = sim.step();
    if (history) history->push_back(r.last);
    ++r.steps;
    const double it = r.last.count("fsi_solver_iterations") ? r.last.at("fsi_solver_iterations") : 0;
    iterations += it;
    r.maxIterations = std::max(r.maxIterations, it);
    if (r.last.count("fsi_energy_change")) r.maxEnergyChange = std::max(r.maxEnergyChange, r.last.at("fsi_energy_change"));
  }
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  r.meanIterations = r.steps > 0 ? iterations / r.steps : 0;
  return r;
}

void channel(const Registry& registry, int finest) {
  const double exact = -(150.0 + 100.0 / 3.0) * 9.8 / 3.0 / (2.0 * 100.0);
  std::printf("channel_plate: v_s = %.5f m/s (analytic)\n\n", exact);
  std::printf("| cells | steps | wall s | v_plate | error | order | mean CG its | max energy change |\n|---|---|---|---|---|---|---|---|\n");
  double previous = 0;
  for (int n = 12; n <= finest; n *= 2) {
    const Run r = runScene(registry, "channel_plate.json",
                           {{"entities.fluid.mac_grid.cells", "[" + std::to_string(n) + "," + std::to_string(n) + "]"}});
    const double v = r.last.at("fsi_plate_velocity_y"), e = std::abs(v - exact);
    char order[16] = "";
    if (previous > 0) std::snprintf(order, sizeof order, "%.2f", std::log2(previous / e));
    std::printf("| %d^2 | %ld | %.1f | %.5f | %.2e | %s | %.1f | %.2e |\n", n, r.steps, r.seconds, v, e, order,
                r.meanIterations, r.maxEnergyChange);
    std::fflush(stdout);
    previous = e;
  }
}

double analyticCylinder(double mu) {
  const double r = 5e-3, L = 2e-2, q = r / L;
  return -(2e3 - 1e3) * 9.8 * r * r / (4 * mu) * (-std::log(q) - 0.9157 + 1.7244 * q * q - 1.7302 * std::pow(q, 4));
}

void cylinder(const Registry& registry, int finest, const std::vector<double>& mus, double endScale, bool withStokes) {
  // The thesis's Table 5.1 (40x160, 80x320, 160x640).
  const std::map<double, std::vector<double>> thesis = {
      {0.1, {-0.1716, -0.1882, -0.1966}},    {0.2, {-0.1254, -0.1359, -0.1417}},
      {0.5, {-0.05983, -0.06438, -0.06721}}, {1.0, {-0.03052, -0.03264, -0.03399}},
      {2.0, {-0.01533, -0.01635, -0.01702}}, {5.0, {-0.006148, -0.006547, -0.006828}},
      {10.0, {-0.003013, -0.003279, -0.003417}}};
  const std::vector<double> stokes = {-0.2945, -0.3241, -0.3390};
  std::printf("| eqn | mu | analytic | cells | t end | steps | wall s | v terminal (fastest) | v at t end | thesis | last-10%% change |\n");
  std::printf("|---|---|---|---|---|---|---|---|---|---|---|\n");
  for (int pass = 0; pass < 2; ++pass)
    for (double mu : mus) {
      const bool isStokes = pass == 1;
      if (isStokes && (mu != 0.1 || !withStokes)) continue;
      // A few viscous times rho r^2 / mu (0.25 s at mu = 0.1), at least 0.15 s, and before the
      // cylinder (starting 0.12 m up) nears the bottom: the terminal velocity is the fastest
      // speed of the run (N-S slows down again near the bottom wall).
      const double end = endScale * (isStokes ? 1.5 : mu < 0.15 ? 0.4 : mu < 0.3 ? 0.3 : 0.15);
      int level = 0;
      for (int n = 40; n <= finest; n *= 2, ++level) {
        std::vector<Override> o = {{"entities.fluid.mac_grid.cells", "[" + std::to_string(n) + "," + std::to_string(4 * n) + "]"},
                                   {"entities.fluid.fluid_material.viscosity", num(mu)},
                                   {"time.end", num(end)}};
        if (isStokes) o.push_back({"solvers.fluid.advection", "none"});
        // The cylinder's velocity near the end of the run, to show whether it is terminal.
        const SceneSpec spec = loadScene(std::string(MONOLITH_SOURCE_DIR) + "/scenarios/scenes/falling_cylinder.json", o);
        Simulation<2> sim(spec, registry, 2);
        const auto t0 = std::chrono::steady_clock::now();
        double v = 0, v90 = 0, fastest = 0;
        long steps = 0;
        while (!sim.finished()) {
          v = sim.step().at("fsi_cylinder_velocity_y");
          fastest = std::min(fastest, v);
          ++steps;
          if (sim.time() <= 0.9 * end) v90 = v;
        }
        const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        const auto& column = isStokes ? stokes : thesis.at(mu);
        char ref[16] = "-";
        if (level < 3) std::snprintf(ref, sizeof ref, "%.5g", column[level]);
        std::printf("| %s | %.1f | %.5g | %dx%d | %.2f | %ld | %.1f | %.5g | %.5g | %s | %.1e |\n", isStokes ? "Stokes" : "N-S",
                    mu, analyticCylinder(mu), n, 4 * n, end, steps, seconds, fastest, v, ref, std::abs(v - v90) / std::abs(v));
        std::fflush(stdout);
      }
    }
}

void preconditioners(const Registry& registry, int finest, double mu) {
  std::printf("falling_cylinder, mu = %g\n\n", mu);
  std::printf("| cells | preconditioner | steps | mean CG its | max CG its | wall s per step |\n|---|---|---|---|---|---|\n");
  for (int n = 20; n <= finest; n *= 2)
    for (const std::string p : {"none", "block_jacobi", "block_exact", "schur"}) {
      if (p == "none" && n > 80) continue;  // 10^4 iterations per solve: minutes per step
      const long steps = 5;
      const Run r = runScene(registry, "falling_cylinder.json",
                             {{"entities.fluid.mac_grid.cells", "[" + std::to_string(n) + "," + std::to_string(4 * n) + "]"},
                              {"entities.fluid.fsi_solver.preconditioner", p},
                              {"solvers.fluid.max_iterations", "100000"},
                              {"entities.fluid.fluid_material.viscosity", num(mu)}},
                             steps);
      std::printf("| %dx%d | %s | %ld | %.1f | %.0f | %.3f |\n", n, 4 * n, p.c_str(), r.steps, r.meanIterations,
                  r.maxIterations, r.seconds / r.steps);
      std::fflush(stdout);
    }
}


void sphere(const Registry& registry, const std::vector<int>& cells) {
  const double exact = -0.02881;  // Stokes 0.05703 m/s times Haberman-Sayre 0.5052 (lambda = 0.25)
  std::printf("| cells | radius in cells | steps | wall s | v terminal | error |\n|---|---|---|---|---|---|\n");
  for (int n : cells) {
    const std::string c = "[" + std::to_string(n) + "," + std::to_string(n) + "," + std::to_string(2 * n) + "]";
    const Run r = runScene<3>(registry, "falling_sphere.json", {{"entities.fluid.mac_grid.cells", c}});
    const double v = r.last.at("fsi_sphere_velocity_z");
    std::printf("| %dx%dx%d | %.1f | %ld | %.1f | %.6f | %.1f %% |\n", n, n, 2 * n, 0.002 / (0.016 / n), r.steps, r.seconds, v,
                100 * std::abs(v - exact) / std::abs(exact));
    std::fflush(stdout);
  }
}

void beam(const Registry& registry, int finest, int reference) {
  auto tip = [&](int n, Run& r) {
    r = runScene(registry, "beam.json", {{"entities.fluid.mac_grid.cells", "[" + std::to_string(n) + "," + std::to_string(n / 2) + "]"}});
    return std::make_pair(r.last.at("fsi_beam_track_x"), r.last.at("fsi_beam_track_y"));
  };
  Run ref;
  const auto x = tip(reference, ref);
  std::printf("reference %dx%d: (%.6f, %.6f), %.1f s, mean its %.1f\n", reference, reference / 2, x.first, x.second,
              ref.seconds, ref.meanIterations);
  std::printf("| cells | wall s | x | y | distance to reference | order | mean its |\n|---|---|---|---|---|---|---|\n");
  double previous = -1;
  for (int n = 32; n <= finest; n *= 2) {
    Run r;
    const auto p = tip(n, r);
    const double e = std::hypot(p.first - x.first, p.second - x.second);
    std::printf("| %dx%d | %.1f | %.6f | %.6f | %.3e | %s | %.1f |\n", n, n / 2, r.seconds, p.first, p.second, e,
                previous > 0 ? num(std::log2(previous / e)).substr(0, 5).c_str() : "", r.meanIterations);
    std::fflush(stdout);
    previous = e;
  }
}

void disk(const Registry& registry, int n) {
  std::vector<std::map<std::string, double>> h;
  const Run r = runScene(registry, "oscillating_disk.json",
                         {{"entities.fluid.mac_grid.cells", "[" + std::to_string(n) + "," + std::to_string(n) + "]"}}, -1, &h);
  std::printf("%dx%d: %ld steps, %.1f s wall, mean its %.1f, max solve energy change %.3e\n", n, n, r.steps, r.seconds,
              r.meanIterations, r.maxEnergyChange);
  for (std::size_t i = 1; i + 1 < h.size(); ++i) {
    const double e0 = h[i - 1].at("deformable_elastic_energy"), e = h[i].at("deformable_elastic_energy"),
                 e1 = h[i + 1].at("deformable_elastic_energy");
    if ((e > e0 && e >= e1) || (e < e0 && e <= e1))
      std::printf("elastic %s at t = %.3f: %.4e J\n", e > e0 ? "max" : "min", h[i].at("time"), e);
  }
  std::printf("total energy %.6e -> %.6e J\n", h.front().at("total_energy"), h.back().at("total_energy"));
}

void vortex(const Registry& registry, double end) {
  std::vector<std::map<std::string, double>> h;
  const Run r = runScene(registry, "vortex_shedding_spring.json", {{"time.end", num(end)}}, -1, &h);
  // Over the second half: mean, half the peak-to-peak of y, and the frequency from the upward
  // crossings of the mean (linear interpolation between steps).
  std::vector<double> t, y;
  for (const auto& m : h)
    if (m.at("time") >= 0.5 * end) {
      t.push_back(m.at("time"));
      y.push_back(m.at("fsi_cylinder_position_y"));
    }
  double mean = 0, lo = 1e300, hi = -1e300, xmean = 0;
  for (double v : y) {
    mean += v / y.size();
    lo = std::min(lo, v);
    hi = std::max(hi, v);
  }
  for (const auto& m : h)
    if (m.at("time") >= 0.5 * end) xmean += m.at("fsi_cylinder_position_x") / y.size();
  std::vector<double> up;
  for (std::size_t i = 1; i < y.size(); ++i)
    if (y[i - 1] < mean && y[i] >= mean) up.push_back(t[i - 1] + (mean - y[i - 1]) / (y[i] - y[i - 1]) * (t[i] - t[i - 1]));
  const double f = up.size() > 1 ? (up.size() - 1) / (up.back() - up.front()) : 0.0;
  std::printf("%ld steps, %.1f s wall, mean its %.1f, max solve energy change %.3e\n", r.steps, r.seconds, r.meanIterations,
              r.maxEnergyChange);
  std::printf("t in [%.1f, %.1f]: mean x %.4f, mean y %.4f, amplitude (half peak-to-peak of y) %.4f D, frequency %.4f Hz "
              "(%zu upward crossings)\n",
              0.5 * end, end, xmean, mean, 0.5 * (hi - lo), f, up.size());
}

}  // namespace

int main(int argc, char** argv) {
  const std::string mode = argc > 1 ? argv[1] : "channel";
  Registry registry;
  registerBuiltins(registry);
  if (mode == "channel") channel(registry, argc > 2 ? std::atoi(argv[2]) : 96);
  else if (mode == "cylinder") {
    std::vector<double> mus = {0.1, 0.2, 0.5, 1.0, 2.0, 5.0, 10.0};
    if (argc > 3 && std::string(argv[3]) != "all") mus = {std::atof(argv[3])};
    cylinder(registry, argc > 2 ? std::atoi(argv[2]) : 80, mus, argc > 4 ? std::atof(argv[4]) : 1.0,
             !(argc > 5 && std::string(argv[5]) == "no_stokes"));
  } else if (mode == "precond") preconditioners(registry, argc > 2 ? std::atoi(argv[2]) : 160, argc > 3 ? std::atof(argv[3]) : 0.1);
  else if (mode == "sphere") {
    std::vector<int> cells;
    for (int i = 2; i < argc; ++i) cells.push_back(std::atoi(argv[i]));
    sphere(registry, cells.empty() ? std::vector<int>{16, 24, 32} : cells);
  } else if (mode == "beam") beam(registry, argc > 2 ? std::atoi(argv[2]) : 128, argc > 3 ? std::atoi(argv[3]) : 256);
  else if (mode == "disk") disk(registry, argc > 2 ? std::atoi(argv[2]) : 64);
  else if (mode == "vortex") vortex(registry, argc > 2 ? std::atof(argv[2]) : 120.0);
  else {
    std::fprintf(stderr, "usage: bench_fsi channel|cylinder|precond|sphere|beam|disk|vortex [finest] ...\n");
    return 2;
  }
  return 0;
}
