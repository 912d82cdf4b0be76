#include "scenarios/runner.h"

#include <sys/stat.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iomanip>
#include <sstream>
#include <stdexcept>

#include <tbb/global_control.h>

#include "scenarios/simulation.h"
#include "scenarios/checkpoint.h"
#include "scenarios/fluid_probes.h"
#include "scenarios/metrics_writer.h"
#include "scenarios/progress.h"
#include "components/mac_grid.h"
#include "components/rigid_body.h"
#include "scenarios/vtk_grid_writer.h"
#include "scenarios/vtk_writer.h"
#include "scenarios/vtk_deformable_writer.h"
#include "scenarios/vtk_front_writer.h"
#include "components/two_phase_flow.h"
#include "components/deformable.h"

namespace monolith {

namespace fs = std::filesystem;

namespace {

using Clock = std::chrono::steady_clock;

// A checkpoint whose world state cannot be restored: rejected input (exit 3), not a runtime
// failure (exit 1), like a checkpoint whose header is bad.
struct CheckpointRejected : std::runtime_error {
  using std::runtime_error::runtime_error;
};

std::string sceneStem(const std::string& file) {
  return fs::path(file).stem().string().empty() ? "scene" : fs::path(file).stem().string();
}

// One run directory per run: runs/<scene>, else runs/<scene>-2, -3, ...
std::string chooseOutDir(const SceneSpec& scene, const RunOptions& options) {
  if (!options.outDir.empty()) return options.outDir;
  if (!scene.outputDirectory.empty()) return scene.outputDirectory;
  const std::string base = "runs/" + sceneStem(scene.file);
  if (!fs::exists(base)) return base;
  for (int k = 2;; ++k)
    if (!fs::exists(base + "-" + std::to_string(k))) return base + "-" + std::to_string(k);
}

std::string frameName(const std::string& kind, long step, const char* extension) {
  std::ostringstream s;
  s << "frames/" << kind << "_" << std::setw(6) << std::setfill('0') << step << extension;
  return s.str();
}

std::string hex(std::uint64_t h) {
  std::ostringstream s;
  s << std::hex << std::setw(16) << std::setfill('0') << h;
  return s.str();
}

template <int d>
class Run {
 public:
  Run(const SceneSpec& scene, Registry& registry, const RunOptions& options, const CheckpointFile* resume)
      : scene_(scene), registry_(registry), options_(options), resume_(resume) {}

  RunResult execute();

 private:
  void writeFrame(long step);
  std::string checkpointPath(long step) const;
  bool guard(long step, std::string& diagnosis) const;
  void writeSummary(const std::string& status, const std::string& diagnosis, long stepsDone,
                    const std::map<std::string, double>& finalDiagnostics, const std::vector<CheckResult>& checks = {});

  const SceneSpec& scene_;
  Registry& registry_;
  RunOptions options_;
  const CheckpointFile* resume_;
  std::unique_ptr<Simulation<d>> sim_;  // world + scheduler, stepped exactly as in tests/benchmarks
  World<d>& world() { return sim_->world(); }
  const World<d>& world() const { return sim_->world(); }
  std::string outDir_;
  // One time series per kind of frame the scene has (rigid bodies, their geometry, the fluid).
  struct FrameSeries {
    std::string kind;
    const char* extension;
    std::function<void(const World<d>&, const std::string&)> write;
    std::unique_ptr<PvdCollection> pvd;
  };
  std::vector<FrameSeries> series_;
  std::unique_ptr<FluidProbeWriter<d>> probes_;
  void setUpFrameSeries();
  std::vector<std::string> checkpoints_;
  double wallTotal_ = 0;
  long checkpointEvery_ = 0;
  int threads_ = 1;
};

template <int d>
void Run<d>::writeFrame(long step) {
  if (scene_.frameEvery == 0 && scene_.frameInterval == 0) return;
  if (probes_) probes_->frame(world(), step);  // profiles are data, written even with --no-frames
  if (!options_.writeFrames) return;
  const double t = sim_->time();
  for (auto& s : series_) {
    const std::string file = frameName(s.kind, step, s.extension);
    s.write(world(), outDir_ + "/" + file);
    s.pvd->add(t, file);
    s.pvd->write();
  }
}

template <int d>
void Run<d>::setUpFrameSeries() {
  auto add = [&](std::string kind, const char* extension, std::function<void(const World<d>&, const std::string&)> write) {
    FrameSeries s{kind, extension, std::move(write), std::make_unique<PvdCollection>(outDir_ + "/" + kind + ".pvd")};
    if (resume_) {  // keep the frames written before the checkpoint, drop later ones
      s.pvd->load();
      s.pvd->truncateAfter(sim_->time() * (1 + 1e-12));
    }
    series_.push_back(std::move(s));
  };
  if (world().template count<RigidBody<d>>() > 0) {
    add("bodies", ".vtp", [](const World<d>& w, const std::string& p) { writeRigidBodyFrame(w, p); });
    add("geometry", ".vtp", [](const World<d>& w, const std::string& p) { writeRigidGeometryFrame(w, p); });
  }
  if (world().template count<MacGrid<d>>() > 0)
    add("fluid", ".vti", [](const World<d>& w, const std::string& p) { writeMacGridFrame(w, p); });
  if (world().template count<Particles<d>>() > 0)
    add("deformables", ".vtu", [](const World<d>& w, const std::string& p) { writeDeformableFrame(w, p); });
  if constexpr (d == 2)
    if (world().template count<TwoPhaseFlow<d>>() > 0)
      add("front", ".vtp", [](const World<d>& w, const std::string& p) { writeFrontFrame(w, p); });
}

template <int d>
std::string Run<d>::checkpointPath(long step) const {
  std::ostringstream s;
  s << outDir_ << "/checkpoints/step_" << std::setw(8) << std::setfill('0') << step << ".ckpt";
  return s.str();
}

// The blow-up guard: every floating-point field of every component must be finite and below
// the scene's guard.max_abs_value.
template <int d>
bool Run<d>::guard(long step, std::string& diagnosis) const {
  for (const auto& [name, pool] : world().pools()) {
    if (auto v = pool->firstViolation(scene_.guardMaxAbs)) {
      std::ostringstream m;
      m << "unstable at step " << step << " (t = " << sim_->time() << "): entity " << world().label(v->entity)
        << ", component " << v->component << ", field " << v->field.field << "[" << v->field.index
        << "] = " << v->field.value
        << (std::isfinite(v->field.value) ? " exceeds guard.max_abs_value = " + std::to_string(scene_.guardMaxAbs)
                                          : " is not finite");
      diagnosis = m.str();
      return false;
    }
  }
  return true;
}

template <int d>
void Run<d>::writeSummary(const std::string& status, const std::string& diagnosis, long stepsDone,
                          const std::map<std::string, double>& finalDiagnostics,
                          const std::vector<CheckResult>& checks) {
  Json s;
  s["scene"] = scene_.file;
  s["description"] = scene_.description;
  s["version"] = MONOLITH_VERSION;
  s["dimension"] = d;
  s["threads"] = threads_;
  s["dt"] = scene_.dt;
  s["steps"] = scene_.steps;
  s["steps_completed"] = stepsDone;
  s["time"] = sim_->time();
  s["cfl"] = scene_.cfl;
  s["total_wall_seconds"] = wallTotal_;
  s["status"] = status;
  if (!diagnosis.empty()) s["diagnosis"] = diagnosis;
  s["state_hash"] = hex(stateHash(world()));
  Json finals = Json::object();
  for (const auto& [k, v] : finalDiagnostics) finals[k] = std::isfinite(v) ? Json(v) : Json(std::to_string(v));
  s["final_diagnostics"] = finals;
  if (!checks.empty()) s["checks"] = checksToJson(checks);
  Json systems = Json::array();
  for (const auto* sys : sim_->scheduler().systems()) systems.push_back({{"name", sys->name()}, {"stage", stageName(sys->stage())}});
  s["systems"] = systems;
  s["skipped_systems"] = sim_->scheduler().skipped();
  s["checkpoints"] = checkpoints_;
  s["entities"] = world().entityCount();
  // Replace, not throw, on invalid UTF-8: a scene path may hold any bytes on POSIX, and a throw
  // here would lose summary.json after the whole run (exit 1).
  writeFileAtomically(outDir_ + "/summary.json", s.dump(2, ' ', false, Json::error_handler_t::replace) + "\n");
}

template <int d>
RunResult Run<d>::execute() {
  RunResult result;
  threads_ = options_.threads > 0 ? options_.threads : scene_.threads;
  // Process-wide cap on parallelism for this run (default 2 threads, --threads N).
  tbb::global_control cap(tbb::global_control::max_allowed_parallelism, static_cast<std::size_t>(threads_));
  sim_ = std::make_unique<Simulation<d>>(scene_, registry_, threads_);
  long firstStep = 0;
  if (resume_) {
    try {
      restoreCheckpointWorld(*resume_, world(), registry_);
    } catch (const std::exception& e) {
      throw CheckpointRejected(e.what());
    }
    // Corrupt payload bytes can decode to NaN/inf, which would make a solver throw (exit 1)
    // instead of the checkpoint being rejected.
    std::string diagnosis;
    if (!guard(resume_->header.step, diagnosis))
      throw CheckpointRejected("restored state fails the blow-up guard: " + diagnosis);
    firstStep = resume_->header.step;
    sim_->restoreClock(firstStep, resume_->header.time);
    sim_->reschedule();  // the restored world may need other systems than the scene's start
  }
  outDir_ = chooseOutDir(scene_, options_);
  result.outDir = outDir_;
  fs::create_directories(outDir_ + "/frames");
  // --checkpoint-every, else the interval of the run being resumed, else the scene's.
  const long checkpointEvery = options_.checkpointEvery >= 0 ? options_.checkpointEvery
                               : resume_                     ? resume_->header.checkpointEvery
                                                             : scene_.checkpointEvery;
  checkpointEvery_ = checkpointEvery;
  if (checkpointEvery > 0) fs::create_directories(outDir_ + "/checkpoints");
  {
    std::ofstream graph(outDir_ + "/step_graph.dot");
    graph << sim_->scheduler().dot();
  }

  setUpFrameSeries();
  CheckEvaluator<d> checks(parseChecks(scene_.json, scene_.file, d), world(), scene_.file, sim_->time());
  probes_ = std::make_unique<FluidProbeWriter<d>>(scene_, world(), outDir_, resume_ ? firstStep : -1);
  MetricsWriter metrics(outDir_ + "/metrics.csv", resume_ ? firstStep : -1);
  if (!resume_) writeFrame(0);

  std::vector<Stage> stages;
  for (Stage s : kAllStages)
    for (const auto* sys : sim_->scheduler().systems())
      if (sys->stage() == s) {
        stages.push_back(s);
        break;
      }

  Progress progress(scene_.endTime, sim_->time(), scene_.steps, options_.progress);
  std::map<std::string, double> lastDiagnostics;
  std::string lastGoodCheckpoint;
  bool converged = false;
  while (!sim_->finished()) {
    const long n = sim_->stepsDone();
    const auto t0 = Clock::now();
    const std::map<std::string, double>* diagnostics = &lastDiagnostics;
    std::string diagnosis;
    bool stepAborted = false;
    try {
      diagnostics = &sim_->step();
    } catch (const std::exception& e) {
      // A solver may throw on the non-finite values of a blow-up before the guard sees them
      // (the energy fix on an infinite angular momentum): that is an instability (exit 4 with
      // a diagnosis), not an internal error (exit 1), when the guard finds the bad value.
      if (guard(n + 1, diagnosis)) throw;
      diagnosis += std::string(" (step aborted: ") + e.what() + ")";
      stepAborted = true;
    }
    const double wall = std::chrono::duration<double>(Clock::now() - t0).count();
    wallTotal_ += wall;
    const long done = n + 1;

    bool ok = !stepAborted && guard(done, diagnosis);
    for (const auto& [k, v] : *diagnostics)
      if (ok && !std::isfinite(v)) {
        ok = false;
        diagnosis = "unstable at step " + std::to_string(done) + ": diagnostic " + k + " is not finite";
      }
    if (!stepAborted)  // an aborted step has no complete diagnostics to report
      metrics.row(done, sim_->time(), sim_->lastDt(), *diagnostics, stages, sim_->scheduler().stageSeconds(), wall);
    if (!ok) {
      progress.finish("stopped: unstable");
      if (!lastGoodCheckpoint.empty()) diagnosis += "; last good checkpoint: " + lastGoodCheckpoint;
      else diagnosis += "; no checkpoint was written (use --checkpoint-every K)";
      result.checks = checks.finish(world(), sim_->time());  // an unstable run's checks fail
      for (auto& c : result.checks) c.pass = false;
      writeSummary("unstable", diagnosis, done, *diagnostics, result.checks);
      result.exitCode = kExitUnstable;
      result.message = diagnosis;
      result.stepsCompleted = done;
      result.wallSeconds = wallTotal_;
      return result;  // the bad state is neither framed nor checkpointed
    }
    if (diagnostics != &lastDiagnostics) lastDiagnostics = *diagnostics;
    checks.observe(world(), *diagnostics, sim_->time());
    probes_->afterStep(world(), done, sim_->time());
    if (sim_->frameDue()) writeFrame(done);
    if (checkpointEvery > 0 && done % checkpointEvery == 0) {
      const std::string path = checkpointPath(done);
      writeCheckpoint(path, CheckpointHeader{d, done, sim_->time(), fs::absolute(scene_.file).string(), scene_.json.dump(), checkpointEvery_, scene_.clock}, world());
      checkpoints_.push_back(path);
      lastGoodCheckpoint = path;
    }
    progress.update(sim_->time(), done);
    if (!scene_.stopDiagnostic.empty()) {  // steady state: the scene's "stop" criterion
      const auto it = diagnostics->find(scene_.stopDiagnostic);
      if (it != diagnostics->end() && it->second < scene_.stopBelow) {
        converged = true;
        break;
      }
    }
  }
  progress.finish((converged ? "converged: " : "done: ") + std::to_string(sim_->stepsDone() - firstStep) + " steps");
  if (converged && sim_->frameDue() == false) writeFrame(sim_->stepsDone());  // the steady state itself
  probes_->frame(world(), sim_->stepsDone());  // profiles of the final state in any case
  result.checks = checks.finish(world(), sim_->time());
  writeSummary(converged ? "converged" : "completed", "", sim_->stepsDone(), lastDiagnostics, result.checks);
  result.stepsCompleted = sim_->stepsDone();
  result.stateHash = stateHash(world());
  result.wallSeconds = wallTotal_;
  return result;
}

template <int d>
RunResult runWithDimension(const SceneSpec& scene, Registry& registry, const RunOptions& options,
                           const CheckpointFile* resume) {
  Run<d> run(scene, registry, options, resume);
  return run.execute();
}

RunResult dispatch(const SceneSpec& scene, Registry& registry, PluginLoader& plugins, const RunOptions& options,
                   const CheckpointFile* resume, const std::string& checkpointPath = "") {
  RunResult r;
  try {
    loadScenePlugins(scene, plugins, registry);
    return scene.dimension == 2 ? runWithDimension<2>(scene, registry, options, resume)
                                : runWithDimension<3>(scene, registry, options, resume);
  } catch (const SceneError& e) {
    r.exitCode = kExitInvalidScene;
    r.message = e.what();
  } catch (const PluginError& e) {
    r.exitCode = kExitInvalidScene;
    r.message = e.what();
  } catch (const CheckpointRejected& e) {
    r.exitCode = kExitInvalidScene;
    r.message = "checkpoint '" + checkpointPath + "': " + e.what();
  } catch (const std::exception& e) {
    r.exitCode = kExitFailure;
    r.message = e.what();
  }
  return r;
}

}  // namespace

RunResult runScene(const SceneSpec& scene, Registry& registry, PluginLoader& plugins, const RunOptions& options) {
  return dispatch(scene, registry, plugins, options, nullptr);
}

bool resumeMayChange(const std::string& key) { return key.rfind("time.", 0) == 0; }

RunResult resumeRun(const std::string& checkpointPath, Registry& registry, PluginLoader& plugins, RunOptions options,
                    const std::vector<Override>& timeOverrides) {
  RunResult r;
  CheckpointFile file;
  SceneSpec scene;
  try {
    file = readCheckpoint(checkpointPath);
    const ClockOrigin& clock = file.header.clock;
    scene = parseScene(file.header.sceneJson, file.header.sceneFile, {}, clock);
    if (!timeOverrides.empty()) {
      for (const auto& o : timeOverrides)
        if (!resumeMayChange(o.first))
          throw std::runtime_error("--set " + o.first + ": a resume may change only " + kResumeSettings +
                                   "; the rest of the run is its checkpointed state");
      const SceneSpec before = scene;
      scene = parseScene(file.header.sceneJson, file.header.sceneFile, timeOverrides, clock);
      // A new fixed step: the clock goes on from the checkpoint's time (ClockOrigin), not n dt.
      if (scene.cfl <= 0 && (before.cfl > 0 || before.dt != scene.dt))
        scene = parseScene(file.header.sceneJson, file.header.sceneFile, timeOverrides,
                           ClockOrigin{file.header.step, file.header.time});
    }
  } catch (const SceneError& e) {
    r.exitCode = kExitInvalidScene;
    r.message = std::string("checkpoint '") + checkpointPath + "': embedded scene: " + e.what();
    return r;
  } catch (const std::exception& e) {
    r.exitCode = kExitInvalidScene;
    r.message = e.what();
    return r;
  }
  if (scene.dimension != file.header.dimension) {
    r.exitCode = kExitInvalidScene;
    r.message = "checkpoint '" + checkpointPath + "': dimension differs from its scene";
    return r;
  }
  // A step beyond the scene's end (corrupt header, or an earlier end given to resume) would
  // silently "complete" without stepping.
  if ((scene.cfl <= 0 && file.header.step > scene.steps) ||
      (scene.cfl > 0 && file.header.time > scene.endTime * (1 + 1e-12))) {
    char where[160];
    std::snprintf(where, sizeof where, "step %ld (t = %g) is beyond the scene's end (t = %g", file.header.step,
                  file.header.time, scene.endTime);
    r.exitCode = kExitInvalidScene;
    r.message = "checkpoint '" + checkpointPath + "': " + where +
                (scene.cfl > 0 ? ")" : ", " + std::to_string(scene.steps) + " steps)") +
                (timeOverrides.empty() ? "" : "; a time.end or time.steps given to resume must lie after the checkpoint");
    return r;
  }
  if (options.outDir.empty()) {  // continue in the run directory the checkpoint belongs to
    const fs::path p = fs::absolute(checkpointPath);
    options.outDir = p.parent_path().filename() == "checkpoints" ? p.parent_path().parent_path().string()
                                                                 : p.parent_path().string();
  }
  return dispatch(scene, registry, plugins, options, &file, checkpointPath);
}

}  // namespace monolith
