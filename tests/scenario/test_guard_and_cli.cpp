// The blow-up guard (exit 4, a diagnosis naming step, entity, component and field, the last
// good checkpoint, no frames of the bad state) and the CLI contract (exit codes, `systems`,
// progress lines, the metrics.csv schema), all through the monolith executable.
#include <gtest/gtest.h>

#include "support/cli_harness.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <regex>
#include <string>
#include <vector>

namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;
using namespace monolith::test;

bool contains(const std::string& haystack, const std::string& needle) { return haystack.find(needle) != std::string::npos; }

std::string spinSliver() { return std::string(MONOLITH_SOURCE_DIR) + "/scenarios/scenes/spin_sliver.json"; }

// --- blow-up guard ---------------------------------------------------------------------------

// "rocket" falls from rest: v_z after n steps of dt = 0.1 is -0.981 n (exact for constant
// gravity), so |v| first exceeds guard.max_abs_value = 10 at step 11 (10.791) while the
// position (-0.04905 n^2 = -5.9 at n = 11) and everything else stay below 10. A static anchor
// comes first so the offending entity is not simply entity #0.
constexpr const char* kFallingScene = R"json({
  "dimension": 3,
  "time": { "dt": 0.1, "steps": 30, "frame_rate": 10 },
  "gravity": [0, 0, -9.81],
  "guard": { "max_abs_value": 10 },
  "entities": [
    { "name": "anchor", "shape": { "type": "box", "half_extents": [1, 1, 1] },
      "rigid_body": { "static": true, "position": [5, 0, 0] } },
    { "name": "rocket", "shape": { "type": "sphere", "radius": 0.1 }, "rigid_body": { "mass": 1 } }
  ]
})json";

TEST(Guard, StopsAtFirstBadStepAndNamesTheLastGoodCheckpoint) {
  TempDir tmp;
  const fs::path scene = tmp.path() / "falling.json", out = tmp.path() / "run";
  writeFile(scene, kFallingScene);
  const CommandResult r =
      run({MONOLITH_CLI, "run", scene.string(), "--out", out.string(), "--checkpoint-every", "4", "--quiet"}, tmp.logs());
  ASSERT_EQ(r.exitCode, 4) << r.err;

  const std::string lastGood = (out / "checkpoints/step_00000008.ckpt").string();
  for (const std::string& text : {r.err, Json::parse(slurp(out / "summary.json"))["diagnosis"].get<std::string>()}) {
    EXPECT_TRUE(contains(text, "step 11")) << text;
    EXPECT_TRUE(contains(text, "'rocket'")) << text;
    EXPECT_TRUE(contains(text, "rigid_body")) << text;
    EXPECT_TRUE(contains(text, "velocity[2]")) << text;  // z, the falling direction
    EXPECT_TRUE(contains(text, "last good checkpoint: " + lastGood)) << text;
  }
  const Json summary = Json::parse(slurp(out / "summary.json"));
  EXPECT_EQ(summary["status"], "unstable");
  EXPECT_EQ(summary["steps_completed"], 11);
  EXPECT_EQ(summary["checkpoints"], Json::array({(out / "checkpoints/step_00000004.ckpt").string(), lastGood}));
  EXPECT_TRUE(fs::exists(lastGood));
  EXPECT_FALSE(fs::exists(out / "checkpoints/step_00000012.ckpt"));

  // The bad state (step 11) is never framed: frames stop at step 10, and the collection too.
  EXPECT_TRUE(fs::exists(out / "frames/bodies_000010.vtp"));
  const std::regex frameName(R"((bodies|geometry)_(\d{6})\.vtp)");
  for (const auto& entry : fs::directory_iterator(out / "frames")) {
    std::smatch m;
    const std::string name = entry.path().filename().string();
    ASSERT_TRUE(std::regex_match(name, m, frameName)) << "unexpected file " << name;
    EXPECT_LE(std::stol(m[2].str()), 10) << name;
  }
  const std::string pvd = slurp(out / "bodies.pvd");
  EXPECT_TRUE(contains(pvd, "frames/bodies_000010.vtp"));
  EXPECT_FALSE(contains(pvd, "frames/bodies_000011.vtp"));
  for (const auto& line : lines(slurp(out / "metrics.csv"))) {
    if (!line.empty() && std::isdigit(static_cast<unsigned char>(line[0]))) {
      EXPECT_LE(std::stol(line), 11) << line;
    }
  }

  // The failure is deterministic: resuming from the last good checkpoint hits it again.
  const CommandResult again =
      run({MONOLITH_CLI, "resume", lastGood, "--out", (tmp.path() / "again").string(), "--quiet"}, tmp.logs());
  EXPECT_EQ(again.exitCode, 4) << again.err;
  EXPECT_TRUE(contains(again.err, "step 11")) << again.err;
}

TEST(Guard, WithoutCheckpointsSaysSo) {
  TempDir tmp;
  const fs::path scene = tmp.path() / "falling.json", out = tmp.path() / "run";
  writeFile(scene, kFallingScene);
  const CommandResult r = run({MONOLITH_CLI, "run", scene.string(), "--out", out.string(), "--quiet"}, tmp.logs());
  ASSERT_EQ(r.exitCode, 4) << r.err;
  EXPECT_TRUE(contains(r.err, "no checkpoint was written")) << r.err;
  EXPECT_FALSE(fs::exists(out / "checkpoints"));
}

// A force of 1e300 on a body of mass 1e-10 overflows the acceleration to inf in the first
// step (the guard limit is raised above the force itself, so the force component passes).
TEST(Guard, OverflowToInfinityIsNotFinite) {
  TempDir tmp;
  const fs::path scene = tmp.path() / "overflow.json", out = tmp.path() / "run";
  writeFile(scene, R"json({
    "dimension": 3, "time": { "dt": 0.1, "steps": 5 }, "guard": { "max_abs_value": 1e301 },
    "entities": [ { "name": "bullet", "shape": { "type": "sphere", "radius": 0.1 }, "rigid_body": { "mass": 1e-10 },
                    "external_force": { "force": [1e300, 0, 0] } } ]
  })json");
  const CommandResult r = run({MONOLITH_CLI, "run", scene.string(), "--out", out.string(), "--quiet"}, tmp.logs());
  ASSERT_EQ(r.exitCode, 4) << r.err;
  const std::string diagnosis = Json::parse(slurp(out / "summary.json"))["diagnosis"];
  EXPECT_TRUE(contains(diagnosis, "step 1 ")) << diagnosis;
  EXPECT_TRUE(contains(diagnosis, "'bullet'")) << diagnosis;
  EXPECT_TRUE(contains(diagnosis, "rigid_body")) << diagnosis;
  EXPECT_TRUE(contains(diagnosis, "position[0]") || contains(diagnosis, "velocity[0]")) << diagnosis;
  EXPECT_TRUE(contains(diagnosis, "not finite")) << diagnosis;
  EXPECT_FALSE(fs::exists(out / "frames/bodies_000001.vtp"));
}

// A torque that overflows the angular momentum makes the rotation solver throw inside the step,
// before the guard runs: that is still an instability (exit 4, summary written), not an
// internal error (it used to exit 1 with only the solver's message).
TEST(Guard, SolverFailureOnOverflowIsReportedAsUnstable) {
  TempDir tmp;
  const fs::path scene = tmp.path() / "torque.json", out = tmp.path() / "run";
  writeFile(scene, R"json({
    "dimension": 3, "time": { "dt": 0.1, "steps": 5 }, "guard": { "max_abs_value": 1e301 },
    "entities": [ { "name": "twister", "shape": { "type": "box", "half_extents": [0.1, 0.2, 0.3] },
                    "rigid_body": { "mass": 1e-10 }, "external_force": { "torque": [1e300, 1e300, 0] } } ]
  })json");
  const CommandResult r = run({MONOLITH_CLI, "run", scene.string(), "--out", out.string(), "--quiet"}, tmp.logs());
  ASSERT_EQ(r.exitCode, 4) << r.err;
  const Json summary = Json::parse(slurp(out / "summary.json"));
  EXPECT_EQ(summary["status"], "unstable");
  const std::string diagnosis = summary["diagnosis"];
  EXPECT_TRUE(contains(diagnosis, "step 1 ")) << diagnosis;
  EXPECT_TRUE(contains(diagnosis, "'twister'")) << diagnosis;
  EXPECT_TRUE(contains(diagnosis, "rigid_body")) << diagnosis;
}

// --- command line ----------------------------------------------------------------------------

TEST(Cli, UsageErrorsExitWith2) {
  TempDir tmp;
  const CommandResult none = run({MONOLITH_CLI}, tmp.logs());
  EXPECT_EQ(none.exitCode, 2);
  EXPECT_TRUE(contains(none.err, "usage")) << none.err;

  const CommandResult unknown = run({MONOLITH_CLI, "frobnicate"}, tmp.logs());
  EXPECT_EQ(unknown.exitCode, 2);
  EXPECT_TRUE(contains(unknown.err, "frobnicate")) << unknown.err;

  const fs::path out = tmp.path() / "run";
  for (const char* threads : {"0", "-1", "two"}) {
    const CommandResult r = run({MONOLITH_CLI, "run", spinSliver(), "--threads", threads, "--out", out.string()}, tmp.logs());
    EXPECT_EQ(r.exitCode, 2) << "--threads " << threads << ": " << r.err;
    EXPECT_TRUE(contains(r.err, "--threads")) << r.err;
  }
  EXPECT_EQ(run({MONOLITH_CLI, "run", spinSliver(), "--bogus-flag"}, tmp.logs()).exitCode, 2);
  EXPECT_EQ(run({MONOLITH_CLI, "run"}, tmp.logs()).exitCode, 2);  // no scene
  EXPECT_FALSE(fs::exists(out)) << "a usage error must not start a run";
}

TEST(Cli, SystemsListsBuiltinsAndPluginTypes) {
  TempDir tmp;
  const CommandResult r = run({MONOLITH_CLI, "systems"}, tmp.logs());
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_TRUE(contains(r.out, "rigid_body")) << r.out;
  EXPECT_TRUE(contains(r.out, "advance_rigid_positions")) << r.out;
  EXPECT_FALSE(contains(r.out, "wind_drag")) << "plugin types only once the plugin is loaded";

  const CommandResult p = run({MONOLITH_CLI, "systems", "--plugin", MONOLITH_WIND_DRAG_PLUGIN}, tmp.logs());
  ASSERT_EQ(p.exitCode, 0) << p.err;
  EXPECT_TRUE(contains(p.out, "wind_drag")) << p.out;
  EXPECT_TRUE(contains(p.out, "rigid_body")) << p.out;

  // By bare name: this build's own plugin directory is searched.
  const CommandResult n = run({MONOLITH_CLI, "systems", "--plugin", "wind_drag"}, tmp.logs());
  ASSERT_EQ(n.exitCode, 0) << n.err;
  EXPECT_TRUE(contains(n.out, "wind_drag")) << n.out;
  const CommandResult u = run({MONOLITH_CLI, "systems", "--plugin", "no_such_plugin"}, tmp.logs());
  EXPECT_EQ(u.exitCode, 3);
  EXPECT_TRUE(contains(u.err, "--plugin no_such_plugin: no plugin no_such_plugin.so in")) << u.err;
}

constexpr const char* kMetricsPrefix =
    "step,time,dt,kinetic_energy,potential_energy,total_energy,linear_momentum_x,linear_momentum_y,"
    "linear_momentum_z,angular_momentum_x,angular_momentum_y,angular_momentum_z,wall_seconds";

TEST(Cli, RunWritesProgressAndMetrics) {
  TempDir tmp;
  const fs::path out = tmp.path() / "run";
  // No --quiet: stderr is a file, so progress comes as plain "progress:" lines.
  const CommandResult r = run({MONOLITH_CLI, "run", spinSliver(), "--out", out.string()}, tmp.logs());
  ASSERT_EQ(r.exitCode, 0) << r.err;
  std::vector<std::string> progress;
  for (const auto& l : lines(r.err))
    if (l.rfind("progress:", 0) == 0) progress.push_back(l);
  ASSERT_FALSE(progress.empty()) << r.err;
  EXPECT_LE(progress.size(), 11u) << "one line per 10%, not one per step";
  EXPECT_TRUE(contains(progress.back(), "100%")) << progress.back();
  EXPECT_TRUE(contains(progress.back(), "300/300")) << progress.back();
  EXPECT_EQ(r.err.find('\r'), std::string::npos) << "no bar redrawing when stderr is not a TTY";

  const auto metrics = lines(slurp(out / "metrics.csv"));
  ASSERT_EQ(metrics.size(), 301u);  // header + one row per step of spin_sliver's 300
  const std::string& header = metrics[0];
  EXPECT_EQ(header.rfind(kMetricsPrefix, 0), 0u) << header;
  const std::regex stageColumn(",stage_[a-z_]+_seconds(,|$)");
  EXPECT_TRUE(std::regex_search(header, stageColumn)) << header;
  const auto columns = std::count(header.begin(), header.end(), ',');
  for (std::size_t i = 1; i < metrics.size(); ++i) {
    EXPECT_EQ(std::count(metrics[i].begin(), metrics[i].end(), ','), columns) << "line " << i + 1;
    EXPECT_EQ(std::stol(metrics[i]), long(i)) << "rows are steps 1..300 in order";
  }
  const Json summary = Json::parse(slurp(out / "summary.json"));
  EXPECT_EQ(summary["status"], "completed");
  EXPECT_EQ(summary["steps_completed"], 300);
}

TEST(Cli, SetOverridesStepsAndQuietSilencesProgress) {
  TempDir tmp;
  const fs::path out = tmp.path() / "run";
  const CommandResult r =
      run({MONOLITH_CLI, "run", spinSliver(), "--out", out.string(), "--set", "time.steps=10", "--quiet"}, tmp.logs());
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_FALSE(contains(r.err, "progress:")) << r.err;
  const auto metrics = lines(slurp(out / "metrics.csv"));
  ASSERT_EQ(metrics.size(), 11u);  // header + 10 rows
  EXPECT_EQ(metrics[0].rfind(kMetricsPrefix, 0), 0u);
  EXPECT_EQ(std::stol(metrics.back()), 10);
  EXPECT_EQ(Json::parse(slurp(out / "summary.json"))["steps"], 10);
}

}  // namespace
