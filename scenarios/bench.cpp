// `monolith bench`: a suite of scenes, each run (as its own process, one at a time so that the
// runs do not compete for the cores) on every thread count `repeat` times; a table of the cost
// per step (min and median), steps per second, the speed-up over the first thread count, whether
// every thread count ends in the same state (hash), and each check's error.
#include <sys/utsname.h>

#include <algorithm>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <map>
#include <sstream>

#include "scenarios/child_process.h"
#include "scenarios/sweep.h"
#include "scenarios/vtk_writer.h"

#ifndef MONOLITH_SOURCE_TREE
#define MONOLITH_SOURCE_TREE "."
#endif

namespace monolith {

namespace fs = std::filesystem;

namespace {

std::string fmt(const char* f, double v) {
  char b[64];
  std::snprintf(b, sizeof b, f, v);
  return b;
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n == 0 ? 0 : n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

std::string machine() {
  utsname u{};
  uname(&u);
  std::ifstream cpu("/proc/cpuinfo");
  std::string line, model;
  while (std::getline(cpu, line))
    if (line.rfind("model name", 0) == 0) {
      model = line.substr(line.find(':') + 2);
      break;
    }
  return std::string(u.nodename) + ", " + (model.empty() ? u.machine : model);
}

struct Entry {
  std::string name, scene;
  std::vector<std::string> sets;
};

}  // namespace

int runBench(const BenchOptions& o) {
  const std::string suiteFile = o.suite.empty() ? std::string(MONOLITH_SOURCE_TREE) + "/scenarios/bench/default.json" : o.suite;
  const Json suite = readJson(suiteFile);
  if (!suite.is_object() || !suite.contains("scenes") || !suite["scenes"].is_array()) {
    std::fprintf(stderr, "monolith: bench suite '%s': expected a JSON object with \"scenes\": [{\"name\", \"scene\", \"set\"}]\n",
                 suiteFile.c_str());
    return 3;
  }
  std::vector<Entry> entries;
  for (std::size_t i = 0; i < suite["scenes"].size(); ++i) {
    const Json& e = suite["scenes"][i];
    if (!e.is_object() || !e.contains("scene") || !e["scene"].is_string()) {
      std::fprintf(stderr, "monolith: %s: scenes[%zu].scene: expected a scene path\n", suiteFile.c_str(), i);
      return 3;
    }
    Entry en;
    en.scene = (fs::path(suiteFile).parent_path() / e["scene"].get<std::string>()).lexically_normal().string();
    en.name = e.value("name", fs::path(en.scene).stem().string());
    if (e.contains("set"))
      for (const auto& s : e["set"]) en.sets.push_back(s.get<std::string>());
    entries.push_back(en);
  }
  fs::create_directories(o.out);
  std::ostringstream csv, md;
  csv << "scene,threads,steps,runs,us_per_step_min,us_per_step_median,steps_per_second,speedup,state_hash,"
         "same_hash_all_threads,exit_code,checks\n";
  std::time_t now = std::time(nullptr);
  char date[32];
  std::strftime(date, sizeof date, "%Y-%m-%d %H:%M UTC", std::gmtime(&now));
  md << "Suite `" << fs::path(suiteFile).filename().string() << "`, " << date << ", " << machine() << ", "
     << o.repeat << " runs per thread count (`monolith bench`).\n\n"
     << "| scene | steps | threads | µs/step min | µs/step median | steps/s | speed-up | same state | check errors |\n"
     << "|---|---:|---:|---:|---:|---:|---:|---|---|\n";
  int worstExit = 0;
  for (const auto& e : entries) {
    struct PerThreads {
      std::vector<double> us;
      std::string hash;
      long steps = 0;
      int exit = 0;
      std::string checks;
    };
    std::map<int, PerThreads> per;
    for (int t : o.threads)
      for (int r = 0; r < o.repeat; ++r) {
        const std::string dir = o.out + "/runs/" + e.name + "_t" + std::to_string(t) + "_r" + std::to_string(r);
        fs::remove_all(dir);
        fs::create_directories(dir);
        std::vector<std::string> args = {"run", e.scene, "--out", dir, "--quiet", "--no-frames", "--threads", std::to_string(t)};
        for (const auto& s : e.sets) args.insert(args.end(), {"--set", s});
        const pid_t pid = spawn(o.executable, args, dir + "/log.txt");
        int status = 0;
        if (pid > 0) waitpid(pid, &status, 0);
        const int code = pid > 0 ? exitCodeOf(status) : 127;
        const Json sj = readJson(dir + "/summary.json");
        PerThreads& p = per[t];
        p.exit = std::max(p.exit, code);
        if (!sj.is_object()) continue;
        p.steps = sj.value("steps_completed", 0L);
        if (p.steps > 0) p.us.push_back(sj.value("total_wall_seconds", 0.0) / p.steps * 1e6);
        p.hash = sj.value("state_hash", std::string());
        if (r == 0 && sj.contains("checks")) {
          std::string c;
          for (const auto& k : sj["checks"])
            c += (c.empty() ? "" : "; ") + k["name"].get<std::string>() + " " +
                 (k["error"].is_number() ? fmt("%.2g", k["error"].get<double>()) : std::string("-")) +
                 (k["pass"].get<bool>() ? "" : " FAIL");
          p.checks = c;
        }
        std::fprintf(stderr, "bench: %s, %d thread(s), run %d: exit %d\n", e.name.c_str(), t, r + 1, code);
      }
    bool same = true;
    for (const auto& [t, p] : per) same = same && !p.hash.empty() && p.hash == per.begin()->second.hash;
    const double base = median(per.begin()->second.us);
    for (const auto& [t, p] : per) {
      worstExit = std::max(worstExit, p.exit);
      const double med = median(p.us), mn = p.us.empty() ? 0 : *std::min_element(p.us.begin(), p.us.end());
      const std::string speedup = med > 0 && base > 0 ? fmt("%.2f", base / med) : "";
      csv << e.name << ',' << t << ',' << p.steps << ',' << p.us.size() << ',' << fmt("%.1f", mn) << ','
          << fmt("%.1f", med) << ',' << (med > 0 ? fmt("%.1f", 1e6 / med) : "") << ',' << speedup << ',' << p.hash << ','
          << (same ? "yes" : "no") << ',' << p.exit << ",\"" << p.checks << "\"\n";
      md << "| " << e.name << " | " << p.steps << " | " << t << " | " << fmt("%.1f", mn) << " | " << fmt("%.1f", med)
         << " | " << (med > 0 ? fmt("%.0f", 1e6 / med) : "") << " | " << speedup << " | "
         << (same ? "yes" : "**no**") << (p.exit ? " (exit " + std::to_string(p.exit) + ")" : "") << " | "
         << p.checks << " |\n";
    }
  }
  writeFileAtomically(o.out + "/bench.csv", csv.str());
  writeFileAtomically(o.out + "/bench.md", md.str());
  std::printf("%s\n(%s/bench.csv, %s/bench.md)\n", md.str().c_str(), o.out.c_str(), o.out.c_str());
  return worstExit == 0 ? 0 : 1;
}

}  // namespace monolith
