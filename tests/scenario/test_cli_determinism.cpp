// Determinism of the whole output, through the CLI: a multi-body scene run with --threads 1 and
// --threads 2 writes identical metrics (every column but the wall times), identical frames
// (byte for byte) and the same state hash.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "support/cli_harness.h"

using namespace monolith::test;
namespace fs = std::filesystem;

namespace {

std::string manyBodies() {
  std::string entities;
  for (int i = 0; i < 300; ++i) {
    char buf[400];
    std::snprintf(buf, sizeof buf,
                  R"(%s{"name": "body%d", "shape": {"type": "%s", %s},
                     "rigid_body": {"mass": %.2f, "position": [%d, %d, 0], "velocity": [0.5, %.1f, 0],
                                    "angular_velocity": [0.3, %.1f, 0.1]}})",
                  i ? "," : "", i, i % 2 ? "box" : "sphere",
                  i % 2 ? R"("half_extents": [0.05, 0.5, 1.5])" : R"("radius": 0.3)", 1.0 + 0.01 * i, i % 17,
                  i / 17, 0.1 * (i % 13), 10.0 - i % 5);
    entities += buf;
  }
  return R"({"dimension": 3, "time": {"dt": 0.03333333333333333, "steps": 45, "frame_rate": 10},
             "gravity": [0, -9.81, 0], "entities": [)" + entities + "]}";
}

// metrics.csv without the timing columns (wall_seconds, stage_*_seconds).
std::vector<std::string> physicsColumns(const std::string& csv) {
  const auto rows = lines(csv);
  std::vector<bool> keep;
  std::vector<std::string> out;
  for (std::size_t r = 0; r < rows.size(); ++r) {
    std::stringstream ss(rows[r]);
    std::string cell, kept;
    for (std::size_t c = 0; std::getline(ss, cell, ','); ++c) {
      if (r == 0) keep.push_back(cell != "wall_seconds" && cell.rfind("stage_", 0) != 0);
      if (c < keep.size() && keep[c]) kept += cell + ",";
    }
    out.push_back(kept);
  }
  return out;
}

}  // namespace

TEST(CliDeterminism, OneAndTwoThreadsWriteIdenticalOutputs) {
  TempDir tmp;
  const fs::path scene = tmp.path() / "many.json";
  writeFile(scene, manyBodies());
  const fs::path one = tmp.path() / "t1", two = tmp.path() / "t2";
  const CommandResult r1 = run({MONOLITH_CLI, "run", scene.string(), "--out", one.string(), "--threads", "1", "--quiet"}, tmp.logs());
  const CommandResult r2 = run({MONOLITH_CLI, "run", scene.string(), "--out", two.string(), "--threads", "2", "--quiet"}, tmp.logs());
  ASSERT_EQ(r1.exitCode, 0) << r1.err;
  ASSERT_EQ(r2.exitCode, 0) << r2.err;

  const auto m1 = physicsColumns(slurp(one / "metrics.csv")), m2 = physicsColumns(slurp(two / "metrics.csv"));
  ASSERT_EQ(m1.size(), 46u);  // header + 45 steps
  EXPECT_EQ(m1, m2);

  int frames = 0;
  for (const auto& entry : fs::directory_iterator(one / "frames")) {
    const fs::path other = two / "frames" / entry.path().filename();
    ASSERT_TRUE(fs::exists(other)) << other;
    EXPECT_EQ(slurp(entry.path()), slurp(other)) << entry.path().filename();
    ++frames;
  }
  EXPECT_EQ(frames, 2 * 16);  // bodies + geometry at steps 0, 3, ..., 45

  const auto s1 = nlohmann::json::parse(slurp(one / "summary.json"));
  const auto s2 = nlohmann::json::parse(slurp(two / "summary.json"));
  EXPECT_EQ(s1["state_hash"], s2["state_hash"]);
  EXPECT_EQ(s1["threads"], 1);
  EXPECT_EQ(s2["threads"], 2);
  EXPECT_EQ(s1["final_diagnostics"], s2["final_diagnostics"]);
}
