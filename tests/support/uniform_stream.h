#pragma once
// A body carried along by a uniform stream: a periodic 2 x 1 box of 40 x 20 cells, the fluid and
// the kinematic body both at velocity (1, 0), 30 steps of 0.01. The exact solution is the stream
// itself and no force on the body, whatever the geometry: any face given a velocity other than
// the body's (or stale, where the body uncovers it) breaks it by O(1).
#include <algorithm>
#include <cmath>
#include <string>

#include "components/mac_grid.h"
#include "components/rigid_body.h"
#include "scenarios/simulation.h"
#include "solvers/mac_layout.h"
#include "support/scenes.h"

namespace monolith::test {

struct StreamResult {
  double worstVelocityError = 0;  // max over faces of |u - U| at the end
  double worstForce = 0;          // max over steps and axes of |F| on the body
  int cutFaces = 0;               // faces partly open at the end (cut faces only)
  Eigen::Vector2d finalPosition = Eigen::Vector2d::Zero();
};

// body: the body entity's geometry and rigid_body members, e.g. "\"shape\": {...}, \"rigid_body\":
// {...}" (named "body"); cellsMode: "cut" or "staircase".
inline StreamResult uniformStream(const std::string& body, const std::string& cellsMode) {
  const Registry registry = builtins();
  Simulation<2> sim(parseScene(R"({ "dimension": 2, "time": { "dt": 0.01, "end": 0.3 },
    "solvers": { "fluid": { "obstacle_cells": ")" + cellsMode + R"(" } },
    "entities": [
      { "name": "fluid",
        "mac_grid": { "cells": [40, 20], "domain_min": [0, 0], "domain_max": [2, 1],
                      "boundaries": { "x_min": { "type": "periodic" }, "x_max": { "type": "periodic" },
                                      "y_min": { "type": "periodic" }, "y_max": { "type": "periodic" } },
                      "initial_velocity": { "type": "uniform", "velocity": [1, 0] } },
        "fluid_material": { "density": 1, "viscosity": 0.01 } },
      { "name": "body", )" + body + R"(, "kinematic": { "velocity": [1, 0] }, "fluid_obstacle": {} } ] })",
                               "uniform_stream.json"),
                    registry, 1);
  StreamResult r;
  while (!sim.finished()) {
    const auto& diag = sim.step();
    r.worstForce = std::max({r.worstForce, std::abs(diag.at("obstacle_body_force_x")), std::abs(diag.at("obstacle_body_force_y"))});
  }
  const MacGrid<2>& grid = sim.world().pool<MacGrid<2>>().components()[0];
  const solvers::MacLayout<2> layout(grid.cells, grid.dx, grid.origin, {true, true});
  for (int f = 0; f < layout.totalFaces(); ++f) {
    r.worstVelocityError = std::max(r.worstVelocityError, std::abs(grid.u[f] - (layout.faceCoord(f).first == 0 ? 1.0 : 0.0)));
    if (!grid.openFraction.empty()) r.cutFaces += grid.openFraction[f] > 0 && grid.openFraction[f] < 1;
  }
  r.finalPosition = sim.world().get<RigidBody<2>>(*sim.world().find("body"))->x;
  return r;
}

}  // namespace monolith::test
