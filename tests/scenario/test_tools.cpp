// The CLI's tools: checks in scenes (run --check), sweeps (resume, failed points, Slurm script
// and --collect), the benchmark suite runner and plots.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>

#include "scenarios/references.h"
#include "support/cli_harness.h"

namespace fs = std::filesystem;
using Json = nlohmann::json;
using namespace monolith;
using namespace monolith::test;

namespace {

const std::string kScenes = std::string(MONOLITH_SOURCE_DIR) + "/scenarios/scenes/";

bool contains(const std::string& haystack, const std::string& needle) { return haystack.find(needle) != std::string::npos; }

Json summaryOf(const fs::path& dir) { return Json::parse(slurp(dir / "summary.json")); }

// sweep.csv as rows of column -> text (no quoted commas in these tables).
std::vector<std::map<std::string, std::string>> readCsv(const fs::path& file) {
  const auto ls = lines(slurp(file));
  std::vector<std::map<std::string, std::string>> rows;
  if (ls.empty()) return rows;
  auto split = [](const std::string& l) {
    std::vector<std::string> out;
    std::stringstream ss(l);
    for (std::string f; std::getline(ss, f, ',');) out.push_back(f);
    if (!l.empty() && l.back() == ',') out.push_back("");
    return out;
  };
  const auto header = split(ls[0]);
  for (std::size_t i = 1; i < ls.size(); ++i) {
    const auto f = split(ls[i]);
    std::map<std::string, std::string> row;
    for (std::size_t k = 0; k < header.size(); ++k) row[header[k]] = k < f.size() ? f[k] : "";
    rows.push_back(row);
  }
  return rows;
}

const std::vector<std::string> kSpinSweep = {"--vary", "time.dt=1/30,1/60,1/120", "--vary",
                                             "solvers.rigid_rotation.order=1,2,3", "--set", "time.end=1"};

}  // namespace

// --- checks ----------------------------------------------------------------------------------

TEST(Checks, SpinSliverPassesWithEnergyMomentumAndOrientationInSummary) {
  TempDir tmp;
  const CommandResult r = run({MONOLITH_CLI, "run", kScenes + "spin_sliver.json", "--out", (tmp.path() / "a").string(),
                               "--quiet", "--no-frames", "--check"},
                              tmp.logs());
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_TRUE(contains(r.out, "check orientation_error")) << r.out;
  const Json s = summaryOf(tmp.path() / "a");
  ASSERT_EQ(s["checks"].size(), 3u);
  std::map<std::string, Json> byName;
  for (const auto& c : s["checks"]) byName[c["name"]] = c;
  EXPECT_TRUE(byName["energy_drift"]["pass"].get<bool>());
  EXPECT_LE(byName["energy_drift"]["error"].get<double>(), 1e-10);
  EXPECT_LE(byName["angular_momentum_drift"]["error"].get<double>(), 1e-12);
  // Second order at 1/30 over 10 s: 0.12 rad from the exact torque-free motion (measured 0.1206).
  EXPECT_NEAR(byName["orientation_error"]["value"].get<double>(), 0.12, 0.01);
}

TEST(Checks, AFailedCheckIsExitCodeFiveOnlyWithCheck) {
  TempDir tmp;
  // First order at frame rate: the orientation is 2.7 rad off after 10 s (tolerance 0.15).
  const std::vector<std::string> base = {MONOLITH_CLI, "run", kScenes + "spin_sliver.json", "--quiet", "--no-frames",
                                         "--set", "solvers.rigid_rotation.order=1"};
  auto with = [&](std::vector<std::string> extra) {
    std::vector<std::string> a = base;
    a.insert(a.end(), extra.begin(), extra.end());
    return a;
  };
  const CommandResult plain = run(with({"--out", (tmp.path() / "a").string()}), tmp.logs());
  EXPECT_EQ(plain.exitCode, 0) << plain.err;
  EXPECT_TRUE(contains(plain.out, "orientation_error            FAIL")) << plain.out;
  const CommandResult checked = run(with({"--out", (tmp.path() / "b").string(), "--check"}), tmp.logs());
  EXPECT_EQ(checked.exitCode, 5) << checked.err;
  EXPECT_FALSE(summaryOf(tmp.path() / "b")["checks"][2]["pass"].get<bool>());
}

TEST(Checks, ShortShippedScenesWithAKnownAnswerPass) {
  // The long ones (pyramid_20, cavity_re100, poiseuille, dfg_2d1) run in tests/support/check_scenes.sh.
  TempDir tmp;
  for (const std::string scene : {"incline_friction", "bounce", "pyramid_2d_10", "pendulum_2d", "chain_2d"}) {
    const CommandResult r = run({MONOLITH_CLI, "run", kScenes + scene + ".json", "--out", (tmp.path() / scene).string(),
                                 "--quiet", "--no-frames", "--check"},
                                tmp.logs());
    EXPECT_EQ(r.exitCode, 0) << scene << ": " << r.out << r.err;
  }
}

TEST(Checks, MistakesNameTheJsonPath) {
  TempDir tmp;
  const std::string head = R"({"dimension": 3, "time": {"dt": 0.1, "steps": 2},
    "entities": [{"name": "ball", "shape": {"type": "sphere", "radius": 1}, "rigid_body": {"mass": 1}}],
    "checks": [)";
  const std::vector<std::pair<std::string, std::string>> cases = {
      {R"({"name": "a", "kind": "bodies", "tolerance": 1})", "checks[0].kind"},
      {R"({"name": "a", "kind": "body", "body": "ball", "reference": 0})", "checks[0].tolerance"},
      {R"({"name": "a", "kind": "body", "body": "ball", "reference": {"analytic": "nope"}, "tolerance": 1})",
       "checks[0].reference.analytic"},
      {R"({"name": "a", "kind": "body", "body": "ball", "reference": {"analytic": "coulomb_incline"}, "tolerance": 1})",
       "checks[0].reference.angle_degrees"},
      {R"({"name": "a", "kind": "body", "body": "ball", "reference": 0, "tolerance": 1, "colour": 1})", "checks[0]"},
      {R"({"name": "a", "kind": "probe", "position": [0, 0, 0], "reference": 0, "tolerance": 1})", "checks[0].kind"},
      {R"({"name": "a", "kind": "body", "body": "cube", "reference": 0, "tolerance": 1})", "checks[0].body"},
  };
  for (std::size_t i = 0; i < cases.size(); ++i) {
    const fs::path scene = tmp.path() / ("bad" + std::to_string(i) + ".json");
    writeFile(scene, head + cases[i].first + "]}");
    const CommandResult r = run({MONOLITH_CLI, "run", scene.string(), "--out", (tmp.path() / "o").string(), "--quiet"},
                                tmp.logs());
    EXPECT_EQ(r.exitCode, 3) << cases[i].first;
    EXPECT_TRUE(contains(r.err, scene.string() + ": " + cases[i].second)) << r.err;
  }
}

TEST(References, TorqueFreeSpinAboutAPrincipalAxisIsAUniformRotation) {
  // L along the body's z principal axis: w = L / I_z about z, q(t) = (cos(wt/2), 0, 0, sin(wt/2)).
  const Eigen::Matrix3d I = Eigen::Vector3d(1.0, 2.0, 3.0).asDiagonal();
  const Eigen::Vector4d q = torqueFreeOrientation({1, 0, 0, 0}, I, {0, 0, 6}, 1.3);
  EXPECT_NEAR(q[0], std::cos(2.0 * 1.3 / 2), 1e-12);
  EXPECT_NEAR(q[3], std::sin(2.0 * 1.3 / 2), 1e-12);
  EXPECT_NEAR(std::hypot(q[1], q[2]), 0, 1e-12);
  // Coulomb: 1/2 g (sin 30 - 0.3 cos 30) t^2 at t = 2.
  const Json p = {{"angle_degrees", 30}, {"friction", 0.3}};
  EXPECT_NEAR(scalarReference("coulomb_incline", p, 2.0, "f", "x"), 0.5 * 9.81 * (0.5 - 0.3 * std::sqrt(0.75)) * 4, 1e-12);
}

// --- sweeps ----------------------------------------------------------------------------------

TEST(Sweep, SpinSliverGivesNineRowsWithCheckColumnsAndResumesWithoutRerunning) {
  TempDir tmp;
  const std::string out = (tmp.path() / "sweep").string();
  std::vector<std::string> cmd = {MONOLITH_CLI, "sweep", kScenes + "spin_sliver.json"};
  cmd.insert(cmd.end(), kSpinSweep.begin(), kSpinSweep.end());
  cmd.insert(cmd.end(), {"--jobs", "2", "--out", out});
  const CommandResult first = run(cmd, tmp.logs());
  ASSERT_EQ(first.exitCode, 0) << first.err;
  EXPECT_TRUE(contains(first.err, "9 points, 9 to run, 2 at a time")) << first.err;
  const auto rows = readCsv(fs::path(out) / "sweep.csv");
  ASSERT_EQ(rows.size(), 9u);
  std::map<std::string, double> error;
  for (const auto& row : rows) {
    EXPECT_EQ(row.at("exit_code"), "0");
    EXPECT_EQ(row.at("status"), "completed");
    EXPECT_EQ(row.count("check_energy_drift_error"), 1u);
    EXPECT_LE(std::stod(row.at("check_energy_drift_error")), 1e-10);
    EXPECT_FALSE(row.at("state_hash").empty());
    EXPECT_FALSE(row.at("final_total_energy").empty());
    error[row.at("time.dt") + "/" + row.at("solvers.rigid_rotation.order")] = std::stod(row.at("check_orientation_error_error"));
  }
  // Same end time for every dt (time.end=1): 30, 60, 120 steps.
  EXPECT_EQ(rows[0].at("steps"), "30");
  EXPECT_EQ(rows[8].at("steps"), "120");
  // Order 2 converges at second order: halving dt divides the orientation error by about 4.
  EXPECT_NEAR(error["1/30/2"] / error["1/60/2"], 4.0, 1.0);
  EXPECT_LT(error["1/30/3"], error["1/30/2"]);
  const std::string before = slurp(fs::path(out) / "sweep.csv");
  const CommandResult second = run(cmd, tmp.logs());
  ASSERT_EQ(second.exitCode, 0) << second.err;
  EXPECT_TRUE(contains(second.err, "9 points, 0 to run")) << second.err;
  EXPECT_EQ(slurp(fs::path(out) / "sweep.csv"), before);
}

TEST(Sweep, AFailedPointIsARowAndAnotherSweepInTheDirectoryIsRefused) {
  TempDir tmp;
  const std::string out = (tmp.path() / "s").string();
  const CommandResult r = run({MONOLITH_CLI, "sweep", kScenes + "spin_sliver.json", "--vary",
                               "solvers.rigid_rotation.order=2,7", "--set", "time.end=0.5", "--out", out},
                              tmp.logs());
  ASSERT_EQ(r.exitCode, 0) << r.err;
  const auto rows = readCsv(fs::path(out) / "sweep.csv");
  ASSERT_EQ(rows.size(), 2u);
  EXPECT_EQ(rows[0].at("exit_code"), "0");
  EXPECT_EQ(rows[1].at("exit_code"), "3");  // order 7 is rejected by the scene's validation
  EXPECT_EQ(rows[1].at("status"), "failed");
  const CommandResult other = run({MONOLITH_CLI, "sweep", kScenes + "spin_sliver.json", "--vary", "time.dt=0.1",
                                   "--set", "time.end=0.5", "--out", out},
                                  tmp.logs());
  EXPECT_EQ(other.exitCode, 2);
  EXPECT_TRUE(contains(other.err, "holds another sweep")) << other.err;
}

TEST(Sweep, SlurmScriptTasksCollectToTheLocalTable) {
  // The array tasks are run here by bash with SLURM_ARRAY_TASK_ID set, as sbatch would run them
  // (a real Slurm round trip is tests/support/slurm_round_trip.sh); --collect must give the
  // table a local sweep gives, state hash for state hash.
  TempDir tmp;
  const std::string local = (tmp.path() / "local").string(), cluster = (tmp.path() / "cluster").string();
  std::vector<std::string> common = {MONOLITH_CLI, "sweep", kScenes + "spin_sliver.json", "--vary",
                                     "time.dt=1/30,1/60", "--vary", "solvers.rigid_rotation.order=1,3", "--set",
                                     "time.end=1"};
  auto with = [&](std::vector<std::string> extra) {
    std::vector<std::string> a = common;
    a.insert(a.end(), extra.begin(), extra.end());
    return a;
  };
  ASSERT_EQ(run(with({"--out", local}), tmp.logs()).exitCode, 0);
  const CommandResult emit = run(with({"--out", cluster, "--emit-slurm"}), tmp.logs());
  ASSERT_EQ(emit.exitCode, 0) << emit.err;
  const std::string script = slurp(fs::path(cluster) / "sweep.slurm");
  EXPECT_TRUE(contains(script, "#SBATCH --array=0-3")) << script;
  EXPECT_FALSE(fs::exists(fs::path(cluster) / "sweep.csv"));
  for (int k = 0; k < 4; ++k) {
    const CommandResult task = run({"env", "SLURM_ARRAY_TASK_ID=" + std::to_string(k), "bash",
                                    (fs::path(cluster) / "sweep.slurm").string()},
                                   tmp.logs());
    ASSERT_EQ(task.exitCode, 0) << task.err;
  }
  const CommandResult collect = run({MONOLITH_CLI, "sweep", "--collect", cluster}, tmp.logs());
  ASSERT_EQ(collect.exitCode, 0) << collect.err;
  const auto a = readCsv(fs::path(local) / "sweep.csv"), b = readCsv(fs::path(cluster) / "sweep.csv");
  ASSERT_EQ(a.size(), 4u);
  ASSERT_EQ(b.size(), 4u);
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].at("state_hash"), b[i].at("state_hash"));
    EXPECT_EQ(a[i].at("check_orientation_error_error"), b[i].at("check_orientation_error_error"));
  }
}

// --- bench and plot --------------------------------------------------------------------------

TEST(Bench, ASuiteGivesCsvAndMarkdownWithSpeedUpAndDeterminism) {
  TempDir tmp;
  const fs::path suite = tmp.path() / "suite.json";
  writeFile(suite, R"({"scenes": [{"name": "sliver", "scene": ")" + kScenes +
                       R"(spin_sliver.json", "set": ["time.end=2"]},
                                  {"name": "pyramid", "scene": ")" + kScenes + R"(pyramid_2d_10.json", "set": ["time.end=0.5"]}]})");
  const std::string out = (tmp.path() / "b").string();
  const CommandResult r = run({MONOLITH_CLI, "bench", suite.string(), "--threads", "1,2", "--repeat", "2", "--out", out},
                              tmp.logs());
  ASSERT_EQ(r.exitCode, 0) << r.err;
  const auto rows = readCsv(fs::path(out) / "bench.csv");
  ASSERT_EQ(rows.size(), 4u);  // 2 scenes x 2 thread counts
  for (const auto& row : rows) {
    EXPECT_EQ(row.at("same_hash_all_threads"), "yes") << row.at("scene");
    EXPECT_EQ(row.at("runs"), "2");
    EXPECT_GT(std::stod(row.at("us_per_step_median")), 0);
    EXPECT_LE(std::stod(row.at("us_per_step_min")), std::stod(row.at("us_per_step_median")));
  }
  EXPECT_EQ(rows[0].at("steps"), "60");
  EXPECT_EQ(rows[1].at("threads"), "2");
  EXPECT_FALSE(rows[1].at("speedup").empty());
  EXPECT_TRUE(contains(slurp(fs::path(out) / "bench.md"), "| sliver | 60 | 2 |"));
}

namespace {
// Width and height from a PNG's IHDR chunk (0, 0 if it is not a PNG).
std::pair<int, int> pngSize(const fs::path& file) {
  const std::string b = slurp(file);
  if (b.size() < 24 || b.compare(1, 3, "PNG") != 0) return {0, 0};
  auto be = [&](std::size_t i) {
    return (static_cast<unsigned char>(b[i]) << 24) | (static_cast<unsigned char>(b[i + 1]) << 16) |
           (static_cast<unsigned char>(b[i + 2]) << 8) | static_cast<unsigned char>(b[i + 3]);
  };
  return {static_cast<int>(be(16)), static_cast<int>(be(20))};
}
}  // namespace

TEST(Plot, RunDirectoryAndSweepFrontArePngs) {
  if (std::system("/usr/bin/python3 -c 'import matplotlib' 2>/dev/null") != 0)
    GTEST_SKIP() << "python3-matplotlib is not installed (cmake/install-deps.sh installs it)";
  TempDir tmp;
  const std::string runDir = (tmp.path() / "run").string(), sweepDir = (tmp.path() / "s").string();
  ASSERT_EQ(run({MONOLITH_CLI, "run", kScenes + "bounce.json", "--out", runDir, "--quiet", "--no-frames", "--set",
                 "time.end=1"},
                tmp.logs())
                .exitCode,
            0);
  const CommandResult p = run({MONOLITH_CLI, "plot", runDir}, tmp.logs());
  ASSERT_EQ(p.exitCode, 0) << p.err;
  const auto [w, h] = pngSize(fs::path(runDir) / "plots.png");
  EXPECT_EQ(w, 900);  // 9 x 3 inches per panel at 100 dpi: energy, momentum, stage times
  EXPECT_EQ(h, 900);
  EXPECT_GT(fs::file_size(fs::path(runDir) / "plots.png"), 20000u);  // drawn curves, not an empty canvas

  std::vector<std::string> cmd = {MONOLITH_CLI, "sweep", kScenes + "spin_sliver.json", "--vary", "time.dt=1/30,1/60",
                                  "--vary", "solvers.rigid_rotation.order=2,3", "--set", "time.end=1", "--out", sweepDir};
  ASSERT_EQ(run(cmd, tmp.logs()).exitCode, 0);
  const std::string png = (tmp.path() / "front.png").string();
  const CommandResult f = run({MONOLITH_CLI, "plot", sweepDir + "/sweep.csv", "--y", "check_orientation_error_error",
                               "--logx", "--logy", "--out", png},
                              tmp.logs());
  ASSERT_EQ(f.exitCode, 0) << f.err;
  EXPECT_EQ(pngSize(png), std::make_pair(800, 450));
  const CommandResult bad = run({MONOLITH_CLI, "plot", sweepDir + "/sweep.csv", "--y", "no_such_column"}, tmp.logs());
  EXPECT_NE(bad.exitCode, 0);
  EXPECT_TRUE(contains(bad.err, "no column 'no_such_column'")) << bad.err;
}

TEST(Plot, FrameOfARunIsAPng) {
  // `plot RUN --frame` draws the run's last ParaView frame: bodies as shaded surfaces, a 2-D
  // fluid as a field image; a run without frames and an unknown field are refused.
  if (std::system("/usr/bin/python3 -c 'import matplotlib, vtk' 2>/dev/null") != 0)
    GTEST_SKIP() << "python3-matplotlib or python3-vtk9 is not installed (cmake/install-deps.sh installs them)";
  TempDir tmp;
  const std::string bodies = (tmp.path() / "bodies").string(), fluid = (tmp.path() / "fluid").string();
  ASSERT_EQ(run({MONOLITH_CLI, "run", kScenes + "pyramid_10.json", "--out", bodies, "--quiet", "--set", "time.end=0.1"},
                tmp.logs())
                .exitCode,
            0);
  const CommandResult b = run({MONOLITH_CLI, "plot", bodies, "--frame", "--view=-30,30"}, tmp.logs());
  ASSERT_EQ(b.exitCode, 0) << b.err;
  EXPECT_EQ(pngSize(fs::path(bodies) / "frame.png"), std::make_pair(800, 500));
  EXPECT_GT(fs::file_size(fs::path(bodies) / "frame.png"), 15000u);  // 56 shaded bodies, not an empty canvas

  ASSERT_EQ(run({MONOLITH_CLI, "run", kScenes + "poiseuille.json", "--out", fluid, "--quiet", "--set", "time.end=0.2"},
                tmp.logs())
                .exitCode,
            0);
  const std::string png = (tmp.path() / "u.png").string();
  const CommandResult f = run({MONOLITH_CLI, "plot", fluid, "--frame", "0.2", "--field", "vorticity", "--out", png},
                              tmp.logs());
  ASSERT_EQ(f.exitCode, 0) << f.err;
  const auto [w, h] = pngSize(png);
  EXPECT_EQ(w, 800);
  EXPECT_GT(h, 200);
  EXPECT_LT(h, 500);  // the 4 x 1 channel keeps its aspect

  const CommandResult bad = run({MONOLITH_CLI, "plot", fluid, "--frame", "--field", "no_such_field"}, tmp.logs());
  EXPECT_NE(bad.exitCode, 0);
  EXPECT_TRUE(contains(bad.err, "unknown field 'no_such_field'")) << bad.err;
  const std::string bare = (tmp.path() / "bare").string();
  ASSERT_EQ(run({MONOLITH_CLI, "run", kScenes + "bounce.json", "--out", bare, "--quiet", "--no-frames", "--set",
                 "time.end=0.01"},
                tmp.logs())
                .exitCode,
            0);
  const CommandResult none = run({MONOLITH_CLI, "plot", bare, "--frame"}, tmp.logs());
  EXPECT_NE(none.exitCode, 0);
  EXPECT_TRUE(contains(none.err, "has no frames")) << none.err;
}

TEST(Checks, ProbeAndProfileChecksSampleTheFluid) {
  // A uniform stream in a doubly periodic box stays uniform (to rounding): the probe reads u = 1
  // and the profile v = 0.5 everywhere; a wrong reference (u = 2) fails with error 1.
  TempDir tmp;
  const fs::path scene = tmp.path() / "stream.json";
  writeFile(scene, R"({"dimension": 2, "time": {"dt": 0.05, "steps": 4},
    "entities": [{"name": "fluid",
      "mac_grid": {"cells": [16, 16], "domain_min": [0, 0], "domain_max": [1, 1],
                   "boundaries": {"x_min": {"type": "periodic"}, "x_max": {"type": "periodic"},
                                  "y_min": {"type": "periodic"}, "y_max": {"type": "periodic"}},
                   "initial_velocity": {"type": "uniform", "velocity": [1, 0.5]}},
      "fluid_material": {"density": 1, "viscosity": 0.01}}],
    "checks": [
      {"name": "probe_u", "kind": "probe", "position": [0.3, 0.7], "field": "u", "reference": 1, "tolerance": 1e-9},
      {"name": "profile_v", "kind": "profile", "field": "v", "from": [0.1, 0.5], "to": [0.9, 0.5], "points": 9,
       "reference": [0.5], "norm": "max", "tolerance": 1e-9},
      {"name": "probe_wrong", "kind": "probe", "position": [0.3, 0.7], "field": "u", "reference": 2, "tolerance": 1e-9}
    ]})");
  const CommandResult r = run({MONOLITH_CLI, "run", scene.string(), "--out", (tmp.path() / "o").string(), "--quiet",
                               "--no-frames", "--check"},
                              tmp.logs());
  EXPECT_EQ(r.exitCode, 5) << r.out << r.err;
  const Json s = summaryOf(tmp.path() / "o");
  ASSERT_EQ(s["checks"].size(), 3u);
  EXPECT_TRUE(s["checks"][0]["pass"].get<bool>()) << s["checks"][0];
  EXPECT_NEAR(s["checks"][0]["value"].get<double>(), 1.0, 1e-9);
  EXPECT_TRUE(s["checks"][1]["pass"].get<bool>()) << s["checks"][1];
  EXPECT_FALSE(s["checks"][2]["pass"].get<bool>());
  EXPECT_NEAR(s["checks"][2]["error"].get<double>(), 1.0, 1e-9);
}
