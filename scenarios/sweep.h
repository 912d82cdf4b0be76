#pragma once
// Parameter sweeps and benchmark suites of the CLI (`monolith sweep`, `monolith bench`). Every
// point of a sweep is its own `monolith run` process (a crash or blow-up is a row, not the end
// of the sweep; TBB's thread cap is per process), J at a time; its run directory holds the
// summary.json the table is built from, so a sweep resumes by skipping points that finished and
// can be spread over a cluster (one Slurm array task per point) and collected afterwards.
#include <string>
#include <utility>
#include <vector>

namespace monolith {

struct SweepOptions {
  std::string scene;
  std::vector<std::pair<std::string, std::vector<std::string>>> vary;  // KEY -> values, as typed
  std::vector<std::pair<std::string, std::string>> sets;               // fixed --set overrides
  int repeat = 1, jobs = 1, threads = 0;                                 // threads 0: the scene's
  std::string out;
  long point = -1;        // >= 0: run only this point (a Slurm array task)
  bool emitSlurm = false;  // write DIR/sweep.slurm instead of running
  std::string executable;  // the monolith binary the points run
};

// Each returns the process exit code (0 ok, 1 I/O, 2 bad command line / another sweep in DIR).
int runSweep(const SweepOptions& options);
int collectSweep(const std::string& dir);

struct BenchOptions {
  std::string suite;  // a suite file; "" = the shipped default (scenarios/bench/default.json)
  std::vector<int> threads = {1, 2};
  int repeat = 3;
  std::string out = "runs/bench";
  std::string executable;
};
int runBench(const BenchOptions& options);

}  // namespace monolith
