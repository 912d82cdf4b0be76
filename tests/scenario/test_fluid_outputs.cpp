// Fluid outputs through the CLI: probes.csv, profiles/*.csv and .vti frames (read back with
// VTK's own reader), on a Poiseuille channel whose values are known in closed form:
// u(y) = 4 U y (1 - y), dp/dx = -8 mu U / h^2 with p = 0 half a cell beyond the outlet.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "support/cli_harness.h"

using namespace monolith::test;
namespace fs = std::filesystem;

namespace {
const char* kScene = R"({ "dimension": 2, "time": { "cfl": 1.0, "end": 20.0, "frame_rate": 1 },
  "stop": { "diagnostic": "fluid_velocity_change", "below": 1e-7 },
  "output": { "probes": [ { "name": "centre", "position": [3.0, 0.5] } ],
              "profiles": [ { "name": "outlet", "from": [3.0, 0.0], "to": [3.0, 1.0], "points": 11 } ] },
  "entities": [ { "name": "fluid",
      "mac_grid": { "cells": [128, 32], "domain_min": [0, 0], "domain_max": [4, 1],
                    "boundaries": { "x_min": { "type": "inflow", "profile": "parabolic", "peak_velocity": 1.0 },
                                    "x_max": { "type": "outflow" }, "y_min": { "type": "wall" }, "y_max": { "type": "wall" } } },
      "fluid_material": { "density": 1, "viscosity": 0.1 } } ] })";

std::vector<double> csvRow(const std::string& line) {
  std::vector<double> v;
  std::stringstream ss(line);
  for (std::string cell; std::getline(ss, cell, ',');) v.push_back(std::stod(cell));
  return v;
}
}  // namespace

TEST(FluidOutputs, ProbesProfilesAndImageFramesHoldTheChannelFlow) {
  TempDir tmp;
  writeFile(tmp.path() / "channel.json", kScene);
  const fs::path out = tmp.path() / "run";
  const CommandResult r = run({MONOLITH_CLI, "run", (tmp.path() / "channel.json").string(), "--out", out.string(), "--quiet"}, tmp.logs());
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_EQ(nlohmann::json::parse(slurp(out / "summary.json"))["status"], "converged");

  // probes.csv: header, then one row per step; the last row is the steady state.
  const auto probeLines = lines(slurp(out / "probes.csv"));
  ASSERT_GE(probeLines.size(), 3u);
  EXPECT_EQ(probeLines[0], "step,time,centre_u,centre_v,centre_p");
  const auto last = csvRow(probeLines.back());
  EXPECT_NEAR(last[2], 1.0, 0.01) << "centre-line speed U within 1 %";
  EXPECT_NEAR(last[3], 0.0, 1e-8);
  // p(3) = (8 mu U / h^2) (4 + dx/2 - 3): the p = 0 ghost sits half a cell past the outlet.
  EXPECT_NEAR(last[4], 0.8 * (1 + 0.5 * 4.0 / 128), 0.01 * 0.8);

  // The final profile across the channel at x = 3.
  std::vector<fs::path> profiles;
  for (const auto& e : fs::directory_iterator(out / "profiles")) profiles.push_back(e.path());
  ASSERT_FALSE(profiles.empty());
  std::sort(profiles.begin(), profiles.end());
  const auto rows = lines(slurp(profiles.back()));
  ASSERT_EQ(rows.size(), 12u);
  EXPECT_EQ(rows[0], "s,x,y,u,v,p");
  for (std::size_t i = 1; i < rows.size(); ++i) {
    const auto v = csvRow(rows[i]);
    EXPECT_NEAR(v[3], 4 * v[2] * (1 - v[2]), 0.01) << "y = " << v[2];  // u(y) within 1 % of U
  }

  // A .vti frame, read by VTK: 128 x 32 cells, spacing 1/32, cell velocity near the centre ~ U.
  const std::string vtiFrame = (out / "frames" / "fluid_000000.vti").string();
  ASSERT_TRUE(fs::exists(vtiFrame));
  std::vector<fs::path> frames;
  for (const auto& e : fs::directory_iterator(out / "frames")) frames.push_back(e.path());
  std::sort(frames.begin(), frames.end());
  const CommandResult vtk = run({"/usr/bin/python3", std::string(MONOLITH_SOURCE_DIR) + "/tests/support/read_vti.py",
                                 frames.back().string()}, tmp.logs());
  if (vtk.exitCode == 77) GTEST_SKIP() << "python3-vtk9 is not installed";
  ASSERT_EQ(vtk.exitCode, 0) << vtk.err;
  const auto image = nlohmann::json::parse(vtk.out);
  EXPECT_EQ(image["dimensions"], nlohmann::json({129, 33, 1}));
  EXPECT_EQ(image["cells"], 128 * 32);
  EXPECT_DOUBLE_EQ(image["spacing"][0].get<double>(), 1.0 / 32);
  // Cell (96, 16): centre (3.016, 0.516): u = 4 y (1 - y) = 0.999 within 1 %.
  const auto& velocity = image["velocity"][16 * 128 + 96];
  EXPECT_NEAR(velocity[0].get<double>(), 4 * 0.515625 * (1 - 0.515625), 0.01);
  EXPECT_NE(std::find(image["arrays"].begin(), image["arrays"].end(), "divergence"), image["arrays"].end());
  EXPECT_NE(slurp(out / "fluid.pvd").find("fluid_000000.vti"), std::string::npos);
}

TEST(FluidOutputs, ProbeOutsideTheGridIsALocatedError) {
  TempDir tmp;
  std::string scene = kScene;
  scene.replace(scene.find("[3.0, 0.5]"), 10, "[5.0, 0.5]");
  writeFile(tmp.path() / "bad.json", scene);
  const CommandResult r = run({MONOLITH_CLI, "run", (tmp.path() / "bad.json").string(), "--out",
                               (tmp.path() / "run").string(), "--quiet"}, tmp.logs());
  EXPECT_EQ(r.exitCode, 3);
  EXPECT_NE(r.err.find("output.probes[0].position: expected a point inside the grid"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(tmp.path() / "run" / "metrics.csv") && !slurp(tmp.path() / "run" / "metrics.csv").empty());
}
