#pragma once
// Runs a shipped scene with the CLI to `end` with a checkpoint every 100 steps, resumes from
// step 100 and compares the two runs' final state hashes (summary.json): the test of
// checkpoint/restart being bitwise. The extra arguments go to the straight run (e.g. "--check").
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "support/cli_harness.h"
#include "support/scenes.h"

namespace monolith::test {

inline void expectResumeMatchesStraightRun(const std::string& scene, const std::string& end,
                                           const std::vector<std::string>& extra = {}) {
  TempDir tmp;
  const std::filesystem::path A = tmp.path() / "A", B = tmp.path() / "B";
  std::vector<std::string> argv = {MONOLITH_CLI, "run", kScenes + scene, "--out", A.string(), "--set", "time.end=" + end,
                                   "--no-frames", "--checkpoint-every", "100", "--quiet"};
  argv.insert(argv.end(), extra.begin(), extra.end());
  const auto a = run(argv, tmp.logs(), 300);
  ASSERT_EQ(a.exitCode, 0) << a.err;
  const auto b = run({MONOLITH_CLI, "resume", (A / "checkpoints" / "step_00000100.ckpt").string(), "--out", B.string(),
                      "--quiet"},
                     tmp.logs(), 300);
  ASSERT_EQ(b.exitCode, 0) << b.err;
  const auto sa = nlohmann::json::parse(slurp(A / "summary.json"));
  const auto sb = nlohmann::json::parse(slurp(B / "summary.json"));
  EXPECT_EQ(sa["state_hash"], sb["state_hash"]);
}

}  // namespace monolith::test
