// Checkpoint/restart through the CLI: a run of 2N steps and a run of N steps + resume + N steps
// must agree bit for bit; damaged checkpoints are rejected cleanly (exit 3, a message naming the
// checkpoint, nothing simulated); resuming in place keeps the earlier metrics rows.
//
// Everything compared here is compared exactly (strings/bytes, not tolerances): a resumed run
// restores the state bitwise and t^n = n dt comes from the step index, so any difference at all
// is a restart bug.
#include <gtest/gtest.h>

#include "ecs/binary_io.h"
#include "support/cli_harness.h"

#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;
using namespace monolith::test;

// Checkpoint runs are small: a hung `resume` should fail within 2 minutes, not the default 5.
constexpr int kCommandTimeoutSeconds = 120;

std::vector<std::string> split(const std::string& line) {
  std::vector<std::string> out;
  std::stringstream ss(line);
  for (std::string f; std::getline(ss, f, ',');) out.push_back(f);
  return out;
}

// metrics.csv as header + rows keyed by step (a duplicated step is a failure).
struct Metrics {
  std::vector<std::string> header;
  std::vector<long> steps;  // in file order
  std::map<long, std::string> rawRows;
  std::map<long, std::vector<std::string>> rows;
};
Metrics readMetrics(const fs::path& p) {
  Metrics m;
  const auto ls = lines(slurp(p));
  EXPECT_FALSE(ls.empty()) << p;
  if (ls.empty()) return m;
  m.header = split(ls[0]);
  for (std::size_t i = 1; i < ls.size(); ++i) {
    const auto fields = split(ls[i]);
    EXPECT_EQ(fields.size(), m.header.size()) << p << " line " << i + 1;
    const long step = std::stol(fields.at(0));
    EXPECT_EQ(m.rows.count(step), 0u) << p << ": step " << step << " appears twice";
    m.steps.push_back(step);
    m.rows[step] = fields;
    m.rawRows[step] = ls[i];
  }
  return m;
}

// Wall-clock columns differ between any two runs; everything else must be identical.
bool isTimingColumn(const std::string& name) {
  return name == "wall_seconds" || name.rfind("stage_", 0) == 0;
}

void expectSameRowsExceptTiming(const Metrics& a, const Metrics& b, long fromStep, long toStep) {
  ASSERT_EQ(a.header, b.header);
  for (long s = fromStep; s <= toStep; ++s) {
    ASSERT_TRUE(a.rows.count(s) && b.rows.count(s)) << "step " << s << " missing";
    for (std::size_t c = 0; c < a.header.size(); ++c) {
      if (!isTimingColumn(a.header[c])) {
        EXPECT_EQ(a.rows.at(s)[c], b.rows.at(s)[c]) << "step " << s << ", column " << a.header[c];
      }
    }
  }
}

std::string frame(long step) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "frames/bodies_%06ld.vtp", step);
  return buf;
}
std::string geometryFrame(long step) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "frames/geometry_%06ld.vtp", step);
  return buf;
}
std::string checkpoint(long step) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "checkpoints/step_%08ld.ckpt", step);
  return buf;
}

// spin_sliver's torque-free sliver (intermediate-axis spin: a sensitive, chaotic rotation) plus
// a second box falling and tumbling under gravity.
constexpr const char* kScene = R"json({
  "description": "spin_sliver plus a falling, tumbling box (checkpoint/restart test)",
  "dimension": 3,
  "time": { "dt": 0.03333333333333333, "steps": 300, "frame_rate": 30 },
  "gravity": [0, 0, -9.81],
  "solvers": { "rigid_rotation": { "order": 2, "energy_fix": true } },
  "entities": [
    { "name": "sliver", "shape": { "type": "box", "half_extents": [0.05, 0.5, 1.5] },
      "rigid_body": { "mass": 1.0, "angular_velocity": [0.1, 10.0, 0.1] } },
    { "name": "faller", "shape": { "type": "box", "half_extents": [0.3, 0.2, 0.1] },
      "rigid_body": { "mass": 2.5, "position": [2, 0, 10], "velocity": [0.5, 0, 1],
                      "angular_velocity": [1, -2, 0.5] } }
  ]
})json";

constexpr long N = 15;

struct Fixture {
  TempDir tmp;
  fs::path scene, logs;
  Fixture() : scene(tmp.path() / "two_bodies.json"), logs(tmp.logs()) { writeFile(scene, kScene); }
  // 2N steps with a checkpoint every N.
  CommandResult straightRun(const fs::path& out) {
    return run({MONOLITH_CLI, "run", scene.string(), "--out", out.string(), "--set", "time.steps=" + std::to_string(2 * N),
                "--checkpoint-every", std::to_string(N), "--quiet"},
               logs, kCommandTimeoutSeconds);
  }
};

TEST(CheckpointRestart, StraightAndResumedRunsAgreeBitwise) {
  Fixture f;
  const fs::path A = f.tmp.path() / "A", B = f.tmp.path() / "B";
  const CommandResult a = f.straightRun(A);
  ASSERT_EQ(a.exitCode, 0) << a.err;
  ASSERT_TRUE(fs::exists(A / checkpoint(N)));
  ASSERT_TRUE(fs::exists(A / checkpoint(2 * N)));

  const CommandResult b = run({MONOLITH_CLI, "resume", (A / checkpoint(N)).string(), "--out", B.string(), "--quiet"},
                              f.logs, kCommandTimeoutSeconds);
  ASSERT_EQ(b.exitCode, 0) << b.err;

  const Json sa = Json::parse(slurp(A / "summary.json")), sb = Json::parse(slurp(B / "summary.json"));
  EXPECT_EQ(sa["status"], "completed");
  EXPECT_EQ(sb["status"], "completed");
  EXPECT_EQ(sa["steps_completed"], 2 * N);
  EXPECT_EQ(sb["steps_completed"], 2 * N);
  EXPECT_EQ(sa["state_hash"], sb["state_hash"]);  // bitwise equal final state

  // The second half did move the bodies (else equal frames would prove nothing) ...
  EXPECT_NE(slurp(A / frame(N)), slurp(A / frame(2 * N)));
  // ... and every frame written after the restart is byte-identical to the straight run's.
  for (long s = N + 1; s <= 2 * N; ++s) {
    ASSERT_TRUE(fs::exists(B / frame(s))) << frame(s);
    EXPECT_EQ(slurp(A / frame(s)), slurp(B / frame(s))) << frame(s);
    EXPECT_EQ(slurp(A / geometryFrame(s)), slurp(B / geometryFrame(s))) << geometryFrame(s);
  }

  const Metrics ma = readMetrics(A / "metrics.csv"), mb = readMetrics(B / "metrics.csv");
  EXPECT_EQ(ma.steps.size(), std::size_t(2 * N));
  ASSERT_FALSE(mb.steps.empty());
  EXPECT_EQ(mb.steps.front(), N + 1);  // a fresh directory holds only the resumed steps
  EXPECT_EQ(mb.steps.back(), 2 * N);
  expectSameRowsExceptTiming(ma, mb, N + 1, 2 * N);
}

// --- damaged checkpoints -------------------------------------------------------------------

// Byte offsets of a format-3 checkpoint (layout in scenarios/checkpoint.h): magic (14 bytes),
// u32 format, u32 endianness probe, u32 sizeof(double), i32 dimension, i64 step, f64 time,
// string scene file, string scene JSON (u64 length + bytes), i64 checkpoint interval, i64 + f64
// clock origin, then the world (and a trailing u64 FNV-1a checksum): vector
// generations, vector alive flags, vector free list (u64 length + items), u64 slot count, one
// name string per slot, u64 pool count, then per pool: name string, u64 count, and per
// component u32 entity index, u32 generation, fields (rigid_body starts with f64 mass).
struct Layout {
  std::size_t format = 14, dimension = 26, step = 30, sceneFile = 46, sceneJson = 0, clock = 0, layouts = 0, world = 0,
              firstPool = 0, firstRecord = 0;
  std::string firstPoolName;
  std::size_t firstLayoutText = 0;  // the first saved component's field layout string
};

// Recomputes the trailing checksum, so that a deliberately damaged field reaches the deeper
// checks (a real corruption is caught by the checksum first: see "flipped_byte").
std::string reseal(std::string b) {
  const std::uint64_t h = monolith::fnv1a(reinterpret_cast<const std::uint8_t*>(b.data()), b.size() - 8);
  std::memcpy(&b[b.size() - 8], &h, 8);
  return b;
}

std::uint64_t u64At(const std::string& b, std::size_t at) {
  std::uint64_t v = 0;
  std::memcpy(&v, b.data() + at, sizeof v);
  return v;
}
template <class T>
void put(std::string& b, std::size_t at, T v) {
  std::memcpy(&b[at], &v, sizeof v);
}

Layout parseLayout(const std::string& b) {
  Layout l;
  l.sceneJson = l.sceneFile + 8 + u64At(b, l.sceneFile);
  l.clock = l.sceneJson + 8 + u64At(b, l.sceneJson) + 8;
  l.layouts = l.clock + 16;
  std::size_t p = l.layouts;
  const std::uint64_t saved = u64At(b, p);
  p += 8;
  for (std::uint64_t i = 0; i < saved; ++i) {
    p += 8 + u64At(b, p);  // component name
    if (i == 0) l.firstLayoutText = p + 8;
    p += 8 + u64At(b, p);  // its field layout
  }
  l.world = p;
  const std::uint64_t slots = u64At(b, p);
  p += 8 + 4 * slots;                // generations (u32)
  p += 8 + u64At(b, p);              // alive flags (u8)
  p += 8 + 4 * u64At(b, p);          // free list (u32)
  p += 8;                            // slot count
  for (std::uint64_t i = 0; i < slots; ++i) p += 8 + u64At(b, p);  // names
  p += 8;                            // pool count
  l.firstPool = p;
  l.firstPoolName = b.substr(p + 8, u64At(b, p));
  l.firstRecord = p + 8 + l.firstPoolName.size() + 8;
  return l;
}

TEST(CheckpointRestart, DamagedCheckpointsAreRejectedCleanly) {
  Fixture f;
  const fs::path A = f.tmp.path() / "A";
  const CommandResult a = f.straightRun(A);
  ASSERT_EQ(a.exitCode, 0) << a.err;
  const std::string good = slurp(A / checkpoint(N));
  const Layout l = parseLayout(good);
  // Sanity of the layout this test relies on (if the format changes, update the offsets).
  ASSERT_EQ(good.substr(0, 13), "MONOLITH-CKPT");
  ASSERT_EQ(u64At(good, l.step), std::uint64_t(N));
  ASSERT_EQ(good[l.sceneJson + 8], '{');
  ASSERT_EQ(l.firstPoolName, "rigid_body");
  ASSERT_EQ(good.substr(l.firstLayoutText, 8), "mass:p8 ");

  std::map<std::string, std::string> damaged;
  for (std::size_t n : {std::size_t(0), std::size_t(10), std::size_t(13), std::size_t(20), l.step + 4,
                        l.sceneJson + 20, l.world + 3, l.firstRecord + 4, (l.firstRecord + good.size()) / 2,
                        good.size() - 8, good.size() - 1})
    damaged["truncated_" + std::to_string(n)] = good.substr(0, n);
  {
    std::string b = good;
    b[0] ^= 0x20;
    damaged["bad_magic"] = b;
    b = good;
    put<std::uint32_t>(b, l.format, 99);
    damaged["future_format"] = reseal(b);
    b = good;
    put<std::int32_t>(b, l.dimension, 7);
    damaged["dimension_7"] = reseal(b);
    b = good;
    put<std::int32_t>(b, l.dimension, 2);  // valid, but the embedded scene is 3-D
    damaged["dimension_mismatch"] = reseal(b);
    b = good;
    put<std::int64_t>(b, l.step, -5);
    damaged["negative_step"] = reseal(b);
    b = good;
    put<std::int64_t>(b, l.step, -(std::int64_t(1) << 60));  // used to hang: the loop ran ~2^60 steps
    damaged["huge_negative_step"] = reseal(b);
    b = good;
    put<std::int64_t>(b, l.step, 1000000);  // beyond the scene's 2N steps
    damaged["step_beyond_end"] = reseal(b);
    b = good;
    put<std::int64_t>(b, l.clock, N + 1);  // a clock origin after the checkpoint's own step
    damaged["clock_origin_after_step"] = reseal(b);
    b = good;
    b[l.sceneJson + 8] = '#';  // the embedded scene is no longer JSON
    damaged["scene_json"] = reseal(b);
    b = good;
    put<std::uint64_t>(b, l.world, std::uint64_t(1) << 40);  // absurd entity-table length
    damaged["entity_table_length"] = reseal(b);
    b = good;
    put<std::uint32_t>(b, l.firstRecord + 4, 7);  // component of an entity generation that never lived
    damaged["stale_entity_handle"] = reseal(b);
    b = good;
    put<double>(b, l.firstRecord + 8, std::nan(""));  // the first body's mass
    damaged["nan_mass"] = reseal(b);
    damaged["trailing_bytes"] = good + std::string("garbage");
    b = good;
    b[l.firstRecord + 9] ^= 0x01;  // one flipped bit in the first body's mass, checksum not resealed
    damaged["flipped_byte"] = b;
  }
  {
    // A build whose rigid body saved "mast" where this one saves "mass": refused by name, not
    // read into the wrong fields.
    std::string b = good;
    b[l.firstLayoutText + 3] = 't';
    const fs::path bad = f.tmp.path() / "other_layout.ckpt", out = f.tmp.path() / "out_other_layout";
    writeFile(bad, reseal(b));
    const CommandResult r =
        run({MONOLITH_CLI, "resume", bad.string(), "--out", out.string(), "--quiet"}, f.logs, kCommandTimeoutSeconds);
    EXPECT_EQ(r.exitCode, 3) << r.err;
    for (const char* m : {"other_layout.ckpt", "component 'rigid_body'", "only in the file: mast:p8", "only here: mass:p8"})
      EXPECT_NE(r.err.find(m), std::string::npos) << m << " in: " << r.err;
    EXPECT_FALSE(fs::exists(out));
  }

  for (const auto& [label, bytes] : damaged) {
    SCOPED_TRACE(label);
    const fs::path bad = f.tmp.path() / ("bad_" + label + ".ckpt"), out = f.tmp.path() / ("out_" + label);
    writeFile(bad, bytes);
    const CommandResult r =
        run({MONOLITH_CLI, "resume", bad.string(), "--out", out.string(), "--quiet"}, f.logs, kCommandTimeoutSeconds);
    EXPECT_EQ(r.exitCode, 3) << r.err;
    EXPECT_NE(r.err.find("checkpoint"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find(bad.filename().string()), std::string::npos) << "message should name the file: " << r.err;
    EXPECT_EQ(r.err.find("terminate"), std::string::npos) << r.err;  // no uncaught exception
    EXPECT_FALSE(fs::exists(out)) << "rejected before writing anything";
  }

  const fs::path missing = f.tmp.path() / "no_such.ckpt";
  const CommandResult r = run({MONOLITH_CLI, "resume", missing.string(), "--quiet"}, f.logs, kCommandTimeoutSeconds);
  EXPECT_EQ(r.exitCode, 3);
  EXPECT_NE(r.err.find("checkpoint"), std::string::npos) << r.err;
  // The checkpoints directory instead of a file in it (an easy slip with shell completion).
  const CommandResult dir = run({MONOLITH_CLI, "resume", (A / "checkpoints").string(), "--quiet"}, f.logs,
                                kCommandTimeoutSeconds);
  EXPECT_EQ(dir.exitCode, 3);
  EXPECT_NE(dir.err.find("a directory, not a checkpoint file"), std::string::npos) << dir.err;

  // The undamaged file still resumes (the rejections above are about the damage).
  const CommandResult ok = run({MONOLITH_CLI, "resume", (A / checkpoint(N)).string(), "--out",
                                (f.tmp.path() / "out_good").string(), "--quiet"},
                               f.logs, kCommandTimeoutSeconds);
  EXPECT_EQ(ok.exitCode, 0) << ok.err;
}

// Resuming without --out continues in the checkpoint's own run directory: metrics rows up to
// the checkpoint are kept as they were, later rows (from the interrupted attempt) are replaced.
TEST(CheckpointRestart, ResumeInPlaceKeepsEarlierRowsAndContinues) {
  Fixture f;
  const fs::path C = f.tmp.path() / "C";
  const CommandResult a = f.straightRun(C);
  ASSERT_EQ(a.exitCode, 0) << a.err;
  const std::string originalSummary = slurp(C / "summary.json");
  const Metrics original = readMetrics(C / "metrics.csv");
  std::map<long, std::string> originalFrames;
  for (long s = 0; s <= 2 * N; ++s) originalFrames[s] = slurp(C / frame(s));

  // Simulate a crash at step N + 7: metrics and frames end there.
  const long crash = N + 7;
  {
    const auto ls = lines(slurp(C / "metrics.csv"));
    std::string kept;
    for (long i = 0; i <= crash; ++i) kept += ls.at(i) + "\n";  // header + rows 1..crash
    writeFile(C / "metrics.csv", kept);
    for (long s = crash + 1; s <= 2 * N; ++s) {
      fs::remove(C / frame(s));
      fs::remove(C / geometryFrame(s));
    }
  }

  const CommandResult r =
      run({MONOLITH_CLI, "resume", (C / checkpoint(N)).string(), "--quiet"}, f.logs, kCommandTimeoutSeconds);
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_NE(r.out.find(C.filename().string()), std::string::npos) << r.out;

  const Metrics m = readMetrics(C / "metrics.csv");  // also fails on a duplicated step
  ASSERT_EQ(m.steps.size(), std::size_t(2 * N));
  for (long s = 1; s <= 2 * N; ++s) EXPECT_EQ(m.steps[s - 1], s);
  // Rows <= N are the original lines, byte for byte (wall_seconds included: not re-run).
  for (long s = 1; s <= N; ++s) EXPECT_EQ(m.rawRows.at(s), original.rawRows.at(s)) << "step " << s;
  expectSameRowsExceptTiming(original, m, N + 1, 2 * N);
  EXPECT_EQ(lines(slurp(C / "metrics.csv")).front().rfind("step,", 0), 0u);

  // Frames deleted by the "crash" are written again, identical to the first attempt's.
  for (long s = 0; s <= 2 * N; ++s) EXPECT_EQ(slurp(C / frame(s)), originalFrames[s]) << frame(s);
  // The collection lists every frame once, in time order.
  const std::string pvd = slurp(C / "bodies.pvd");
  std::vector<std::string> files;
  const std::regex ds("file=\"([^\"]+)\"");
  for (auto it = std::sregex_iterator(pvd.begin(), pvd.end(), ds); it != std::sregex_iterator(); ++it)
    files.push_back((*it)[1]);
  ASSERT_EQ(files.size(), std::size_t(2 * N + 1));
  for (long s = 0; s <= 2 * N; ++s) EXPECT_EQ(files[s], frame(s));

  const Json before = Json::parse(originalSummary), after = Json::parse(slurp(C / "summary.json"));
  EXPECT_EQ(after["status"], "completed");
  EXPECT_EQ(after["steps_completed"], 2 * N);
  EXPECT_EQ(after["state_hash"], before["state_hash"]);
}

// --- resume --set time.* -------------------------------------------------------------------

// A longer end given on resume: the same state, bit for bit, as a run that had that end from
// the start (the step is unchanged, so t^n = n dt as before).
TEST(CheckpointRestart, ResumeWithALaterEndMatchesTheLongerRunBitwise) {
  Fixture f;
  const fs::path A = f.tmp.path() / "A", L = f.tmp.path() / "L", B = f.tmp.path() / "B";
  ASSERT_EQ(f.straightRun(A).exitCode, 0);
  const CommandResult l = run({MONOLITH_CLI, "run", f.scene.string(), "--out", L.string(), "--set",
                               "time.steps=" + std::to_string(3 * N), "--quiet"},
                              f.logs, kCommandTimeoutSeconds);
  ASSERT_EQ(l.exitCode, 0) << l.err;
  const CommandResult b = run({MONOLITH_CLI, "resume", (A / checkpoint(2 * N)).string(), "--out", B.string(), "--set",
                               "time.steps=" + std::to_string(3 * N), "--quiet"},
                              f.logs, kCommandTimeoutSeconds);
  ASSERT_EQ(b.exitCode, 0) << b.err;
  const Json sl = Json::parse(slurp(L / "summary.json")), sb = Json::parse(slurp(B / "summary.json"));
  EXPECT_EQ(sb["steps_completed"], 3 * N);
  EXPECT_EQ(sl["state_hash"], sb["state_hash"]);
  expectSameRowsExceptTiming(readMetrics(L / "metrics.csv"), readMetrics(B / "metrics.csv"), 2 * N + 1, 3 * N);
}

// The fixture's scene with an "end" instead of "steps", stepped at dt = 0.02 to t = 0.6 with a
// checkpoint every 10 steps.
struct EndFixture : Fixture {
  static constexpr double kDt = 0.02;
  fs::path A;
  EndFixture() : A(tmp.path() / "A") {
    std::string text = kScene;
    const std::string steps = "\"steps\": 300";
    text.replace(text.find(steps), steps.size(), "\"end\": 10");
    writeFile(scene, text);
  }
  CommandResult runToEnd() {
    return run({MONOLITH_CLI, "run", scene.string(), "--out", A.string(), "--set", "time.dt=0.02", "--set",
                "time.end=0.6", "--checkpoint-every", "10", "--quiet"},
               logs, kCommandTimeoutSeconds);
  }
  CommandResult resume(const fs::path& ckpt, const fs::path& out, const std::vector<std::string>& sets) {
    std::vector<std::string> cmd = {MONOLITH_CLI, "resume", ckpt.string(), "--out", out.string(), "--quiet"};
    for (const auto& s : sets) cmd.insert(cmd.end(), {"--set", s});
    return run(cmd, logs, kCommandTimeoutSeconds);
  }
};

// A new step on resume: the clock goes on from the checkpoint's time, t^n = t_10 + (n - 10) dt',
// the end stays 0.6 (40 steps of 0.01 after t = 0.2), and a checkpoint written after the
// change resumes bitwise (it carries the clock origin). Resuming with the same dt given again
// is the straight run, bitwise.
TEST(CheckpointRestart, ResumeWithANewStepContinuesTheClockFromTheCheckpoint) {
  EndFixture f;
  ASSERT_EQ(f.runToEnd().exitCode, 0);
  const double t10 = 10 * EndFixture::kDt;  // the checkpoint's time, as the run computed it

  const fs::path B = f.tmp.path() / "B";
  const CommandResult b = f.resume(f.A / checkpoint(10), B, {"time.dt=0.01"});
  ASSERT_EQ(b.exitCode, 0) << b.err;
  const Metrics mb = readMetrics(B / "metrics.csv");
  ASSERT_EQ(mb.steps.size(), 40u);
  const auto timeColumn = std::find(mb.header.begin(), mb.header.end(), "time") - mb.header.begin();
  const auto dtColumn = std::find(mb.header.begin(), mb.header.end(), "dt") - mb.header.begin();
  for (long n = 11; n <= 50; ++n) {
    EXPECT_EQ(std::stod(mb.rows.at(n).at(timeColumn)), t10 + static_cast<double>(n - 10) * 0.01) << "step " << n;
    EXPECT_EQ(std::stod(mb.rows.at(n).at(dtColumn)), 0.01) << "step " << n;
  }
  const Json sb = Json::parse(slurp(B / "summary.json"));
  EXPECT_EQ(sb["steps_completed"], 50);
  EXPECT_NEAR(sb["time"].get<double>(), 0.6, 1e-12);
  // The finer second half moved the bodies differently from the straight run.
  EXPECT_NE(sb["state_hash"], Json::parse(slurp(f.A / "summary.json"))["state_hash"]);

  const fs::path C = f.tmp.path() / "C";
  ASSERT_TRUE(fs::exists(B / checkpoint(30)));
  const CommandResult c = f.resume(B / checkpoint(30), C, {});
  ASSERT_EQ(c.exitCode, 0) << c.err;
  EXPECT_EQ(Json::parse(slurp(C / "summary.json"))["state_hash"], sb["state_hash"]);
  expectSameRowsExceptTiming(mb, readMetrics(C / "metrics.csv"), 31, 50);

  const fs::path D = f.tmp.path() / "D";
  const CommandResult same = f.resume(f.A / checkpoint(10), D, {"time.dt=0.02"});
  ASSERT_EQ(same.exitCode, 0) << same.err;
  EXPECT_EQ(Json::parse(slurp(D / "summary.json"))["state_hash"],
            Json::parse(slurp(f.A / "summary.json"))["state_hash"]);
}

// Resume settings that cannot hold: a non-time key (exit 2), an end before the checkpoint, and
// a step that does not divide the time left (exit 3); each names what was wrong, and nothing
// is written.
TEST(CheckpointRestart, ResumeRejectsSettingsItCannotHonour) {
  EndFixture f;
  ASSERT_EQ(f.runToEnd().exitCode, 0);
  struct Case {
    std::string set;
    int exitCode;
    std::vector<std::string> inMessage;
  };
  const std::vector<Case> cases = {
      {"entities.faller.rigid_body.mass=3", 2, {"time settings", "entities.faller.rigid_body.mass"}},
      {"time.end=0.1", 3, {"step 10 (t = 0.2) is beyond the scene's end (t = 0.1, 5 steps)", "time.end"}},
      {"time.dt=0.03", 3, {"time.end", "whole number of steps of dt = 0.03 after the checkpoint's t = 0.2"}},
      {"time.dt=-1", 3, {"time.dt"}},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.set);
    const fs::path out = f.tmp.path() / "rejected";
    const CommandResult r = f.resume(f.A / checkpoint(10), out, {c.set});
    EXPECT_EQ(r.exitCode, c.exitCode) << r.err;
    for (const auto& m : c.inMessage) EXPECT_NE(r.err.find(m), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(out));
  }
}

// Checkpoints written before the clock origin existed (format 2) still resume, bitwise.
TEST(CheckpointRestart, FormatTwoCheckpointsStillResume) {
  Fixture f;
  const fs::path A = f.tmp.path() / "A", B = f.tmp.path() / "B";
  ASSERT_EQ(f.straightRun(A).exitCode, 0);
  std::string b = slurp(A / checkpoint(N));
  const Layout l = parseLayout(b);
  b.erase(l.clock, l.world - l.clock);  // clock origin and component layouts
  put<std::uint32_t>(b, l.format, 2);
  const fs::path old = f.tmp.path() / "format2.ckpt";
  writeFile(old, reseal(b));
  const CommandResult r = run({MONOLITH_CLI, "resume", old.string(), "--out", B.string(), "--quiet"}, f.logs,
                              kCommandTimeoutSeconds);
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_EQ(Json::parse(slurp(B / "summary.json"))["state_hash"], Json::parse(slurp(A / "summary.json"))["state_hash"]);
}

// Format 3 (no component layouts): rigid bodies still resume bitwise; a component whose saved
// fields have changed since is refused by name.
TEST(CheckpointRestart, FormatThreeCheckpointsResumeOnlyUnchangedComponents) {
  Fixture f;
  const fs::path A = f.tmp.path() / "A", B = f.tmp.path() / "B";
  ASSERT_EQ(f.straightRun(A).exitCode, 0);
  const auto downgrade = [](std::string b) {
    const Layout l = parseLayout(b);
    b.erase(l.layouts, l.world - l.layouts);
    put<std::uint32_t>(b, l.format, 3);
    return reseal(b);
  };
  const fs::path old = f.tmp.path() / "format3.ckpt";
  writeFile(old, downgrade(slurp(A / checkpoint(N))));
  const CommandResult r = run({MONOLITH_CLI, "resume", old.string(), "--out", B.string(), "--quiet"}, f.logs,
                              kCommandTimeoutSeconds);
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_EQ(Json::parse(slurp(B / "summary.json"))["state_hash"], Json::parse(slurp(A / "summary.json"))["state_hash"]);

  // A sleeping box on a shelf: its "sleep" component has gained fields since format 3.
  const fs::path scene = f.tmp.path() / "sleeper.json", C = f.tmp.path() / "C", D = f.tmp.path() / "D";
  writeFile(scene, R"json({
    "dimension": 3, "time": { "dt": 0.03333333333333333, "steps": 4 }, "gravity": [0, 0, -9.81],
    "solvers": { "contact": { "sleep": true } },
    "entities": [
      { "name": "shelf", "shape": { "type": "box", "half_extents": [2, 2, 0.1] }, "collider": {},
        "rigid_body": { "static": true } },
      { "name": "box", "shape": { "type": "box", "half_extents": [0.2, 0.2, 0.2] }, "collider": {}, "sleep": {},
        "rigid_body": { "mass": 1, "position": [0, 0, 0.31] } }
    ]
  })json");
  const CommandResult c = run({MONOLITH_CLI, "run", scene.string(), "--out", C.string(), "--checkpoint-every", "2", "--quiet"},
                              f.logs, kCommandTimeoutSeconds);
  ASSERT_EQ(c.exitCode, 0) << c.err;
  const fs::path sleeper = f.tmp.path() / "sleeper3.ckpt";
  writeFile(sleeper, downgrade(slurp(C / checkpoint(2))));
  const CommandResult d = run({MONOLITH_CLI, "resume", sleeper.string(), "--out", D.string(), "--quiet"}, f.logs,
                              kCommandTimeoutSeconds);
  EXPECT_EQ(d.exitCode, 3) << d.err;
  for (const char* m : {"sleeper3.ckpt", "format 3", "component 'sleep'", "run the scene again from its start"})
    EXPECT_NE(d.err.find(m), std::string::npos) << m << " in: " << d.err;
  EXPECT_FALSE(fs::exists(D / "summary.json"));
}

}  // namespace

// Runs a scene from the repository's scenes to `end` with a checkpoint every 30 steps, resumes
// the checkpoint of step 30 into a second directory, and expects the same final state hash and
// the same metrics rows (timings aside) over steps 31-60.
// `settings`: more "--set" overrides of the straight run; `every`: the checkpoint interval, each
// checkpoint before the last is resumed.
static void expectStraightAndResumedRunsAgree(const std::string& name, const std::string& end,
                                              const std::vector<std::string>& settings = {}, int every = 30) {
  TempDir tmp;
  const fs::path scene = fs::path(MONOLITH_SOURCE_DIR) / "scenarios" / "scenes" / (name + ".json");
  const fs::path A = tmp.path() / "A";
  std::vector<std::string> command = {MONOLITH_CLI, "run", scene.string(), "--out", A.string(), "--set", "time.end=" + end,
                                      "--no-frames", "--checkpoint-every", std::to_string(every), "--quiet"};
  for (const auto& s : settings) command.insert(command.end(), {"--set", s});
  const CommandResult a = run(command, tmp.logs(), kCommandTimeoutSeconds);
  ASSERT_EQ(a.exitCode, 0) << a.err;
  const Json sa = Json::parse(slurp(A / "summary.json"));
  EXPECT_EQ(sa["steps_completed"], 60) << name;
  for (int from = every; from < 60; from += every) {
    const fs::path B = tmp.path() / ("B" + std::to_string(from));
    const CommandResult b = run({MONOLITH_CLI, "resume", (A / checkpoint(from)).string(), "--out", B.string(), "--quiet"},
                                tmp.logs(), kCommandTimeoutSeconds);
    ASSERT_EQ(b.exitCode, 0) << b.err;
    const Json sb = Json::parse(slurp(B / "summary.json"));
    EXPECT_EQ(sa["state_hash"], sb["state_hash"]) << name << " resumed from step " << from;
    expectSameRowsExceptTiming(readMetrics(A / "metrics.csv"), readMetrics(B / "metrics.csv"), from + 1, 60);
  }
}

// Contact scenes: nothing of the collision/contact systems survives a step except
// caches, so resuming from a checkpoint must reproduce the straight run bitwise, with a
// kinematic platform (elevator) and with a stack being scattered (box_stack_scatter).
TEST(CheckpointRestart, ContactScenesResumeBitwise) {
  for (const std::string name : {"elevator", "box_stack_scatter"}) expectStraightAndResumedRunsAgree(name, "2.0");
}

// With sleeping on (systems/sleep.h) the stack of box_stack_scatter falls asleep in step 32 and
// the boulder wakes it in step 58: resumed from step 15 and 30 (bodies still, not yet asleep:
// their still time must carry over) and 45 (asleep), each run must reproduce the straight one.
TEST(CheckpointRestart, SleepingBodiesResumeBitwise) {
  expectStraightAndResumedRunsAgree("box_stack_scatter", "2.0", {"solvers.contact.sleep=true"}, 15);
}

// A static obstacle in a fluid with cut faces (dfg_2d2: cut faces, wall at the disk's surface):
// the rasterization is reused while the obstacle keeps still and is not checkpointed, so a
// resumed run rasterizes afresh on its first step and must still reproduce the straight run
// bitwise, obstacle forces included.
TEST(CheckpointRestart, FluidObstacleSceneResumesBitwise) { expectStraightAndResumedRunsAgree("dfg_2d2", "0.24"); }

// A two-way coupled body (falling_cylinder, coarse): the coupling operators are rebuilt every
// step from the checkpointed body and fluid, and the half-step solve's bookkeeping lives within a
// step, so a resumed run must reproduce the straight one bitwise.
TEST(CheckpointRestart, FluidStructureSceneResumesBitwise) {
  expectStraightAndResumedRunsAgree("falling_cylinder", "0.12", {"entities.fluid.mac_grid.cells=[20,80]"});
}
