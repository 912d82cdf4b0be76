#pragma once
// A kinematic obstacle started suddenly at velocity (1, 0, ...) in fluid at rest, inviscid, no
// advection, one step, in a closed box [-half, half]^d: the pressure impulse on it is minus its
// potential-flow added mass (times U = 1), the check of an obstacle's geometry in the pressure.
#include <string>
#include <utility>

#include "scenarios/simulation.h"
#include "support/scenes.h"

namespace monolith::test {

// geometry: the body's geometry members, e.g. "\"shape\": { \"type\": \"disk\", \"radius\": 0.1 }"
// or a "level_set"; position: a JSON point; cellsMode: "cut" or "staircase"; extraBody: more
// rigid_body members (e.g. ", \"angle\": 0.5"). Returns the force impulse along x and the
// largest constraint divergence after the projection.
template <int d>
std::pair<double, double> startedObstacle(const std::string& cells, double half, const std::string& geometry,
                                          const std::string& position, const std::string& cellsMode,
                                          const std::string& extraBody = "") {
  const Registry registry = builtins();
  std::string lo = "[", hi = "[";
  for (int a = 0; a < d; ++a) {
    lo += (a ? "," : "") + std::to_string(-half);
    hi += (a ? "," : "") + std::to_string(half);
  }
  lo += "]", hi += "]";
  std::string walls = R"("x_min": { "type": "wall" }, "x_max": { "type": "wall" }, "y_min": { "type": "wall" }, "y_max": { "type": "wall" })";
  if (d == 3) walls += R"(, "z_min": { "type": "wall" }, "z_max": { "type": "wall" })";
  const std::string velocity = d == 2 ? "[1, 0]" : "[1, 0, 0]";
  Simulation<d> sim(parseScene(R"({ "dimension": )" + std::to_string(d) + R"(, "time": { "dt": 0.001, "end": 0.001 },
    "solvers": { "fluid": { "advection": "none", "tolerance": 1e-12, "obstacle_cells": ")" + cellsMode + R"(" } },
    "entities": [
      { "name": "fluid", "mac_grid": { "cells": )" + cells + R"(, "domain_min": )" + lo + R"(, "domain_max": )" + hi + R"(,
                                       "boundaries": { )" + walls + R"( } },
        "fluid_material": { "density": 1, "viscosity": 0 } },
      { "name": "body", )" + geometry + R"(, "rigid_body": { "mass": 1, "inertia": )" + (d == 2 ? "1" : "[1, 1, 1]") +
                                   R"(, "position": )" + position + extraBody + R"( },
        "kinematic": { "velocity": )" + velocity + R"( }, "fluid_obstacle": {} } ] })",
                               "started_obstacle.json"),
                    registry, 1);
  const auto& diag = sim.step();
  return {diag.at("obstacle_body_force_x") * 0.001, diag.at("fluid_divergence_max")};
}

}  // namespace monolith::test
