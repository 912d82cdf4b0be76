// Taylor-Green vortex at t = 1 (dt = dx / 2): L-infinity velocity error and wall time for both
// advection schemes (and WENO5) and both projections, 32^2 to 128^2, with the observed order.
//
// usage: bench_taylor_green [threads]
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "support/taylor_green.h"

int main(int argc, char** argv) {
  const int threads = argc > 1 ? std::atoi(argv[1]) : 1;
  monolith::Registry registry;
  monolith::registerBuiltins(registry);
  std::printf("| advection | projection | cells | steps | L-inf error | observed order | wall s |\n|---|---|---|---|---|---|---|\n");
  for (const char* advection : {"semi_lagrangian", "eno3", "weno5"})
    for (const char* projection : {"coupled", "chorin"}) {
      double previous = 0;
      for (int n : {32, 64, 128}) {
        const auto r = monolith::test::taylorGreen(n, advection, projection, registry, threads);
        char order[16] = "";
        if (previous > 0) std::snprintf(order, sizeof order, "%.2f", std::log2(previous / r.error));
        std::printf("| %s | %s | %d^2 | %ld | %.3e | %s | %.2f |\n", advection, projection, n, r.steps, r.error, order, r.seconds);
        previous = r.error;
      }
    }
  return 0;
}
