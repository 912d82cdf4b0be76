#include "scenarios/sweep.h"

#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <map>
#include <set>
#include <sstream>

#include "ecs/config.h"
#include "scenarios/child_process.h"
#include "scenarios/vtk_writer.h"


namespace monolith {

namespace fs = std::filesystem;

namespace {

std::string pointDir(const std::string& out, long k) {
  std::ostringstream s;
  s << out << "/points/" << std::setw(4) << std::setfill('0') << k;
  return s.str();
}

std::string csvField(const std::string& v) {
  if (v.find_first_of(",\"\n") == std::string::npos) return v;
  std::string q = "\"";
  for (char c : v) q += c == '"' ? std::string("\"\"") : std::string(1, c);
  return q + "\"";
}

std::string num(double v) {
  if (!std::isfinite(v)) return std::isnan(v) ? "nan" : (v > 0 ? "inf" : "-inf");
  char b[32];
  std::snprintf(b, sizeof b, "%.10g", v);
  return b;
}

std::string shellQuote(const std::string& s) {
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}


// The points of a sweep: the product of the values (the last --vary fastest), each repeated.
struct Point {
  std::vector<std::string> values;
  int repeat = 0;
};
std::vector<Point> points(const Json& def) {
  std::vector<Point> out{{{}, 0}};
  for (const auto& v : def["vary"]) {
    std::vector<Point> next;
    for (const auto& p : out)
      for (const auto& value : v["values"]) {
        Point q = p;
        q.values.push_back(value.get<std::string>());
        next.push_back(q);
      }
    out = next;
  }
  std::vector<Point> repeated;
  for (const auto& p : out)
    for (int r = 0; r < def["repeat"].get<int>(); ++r) repeated.push_back({p.values, r});
  return repeated;
}

Json definitionOf(const SweepOptions& o) {
  Json def;
  def["scene"] = fs::absolute(o.scene).string();
  def["vary"] = Json::array();
  for (const auto& [key, values] : o.vary) def["vary"].push_back({{"key", key}, {"values", values}});
  def["set"] = Json::array();
  for (const auto& [k, v] : o.sets) def["set"].push_back(k + "=" + v);
  def["repeat"] = o.repeat;
  def["threads"] = o.threads;
  return def;
}

std::vector<std::string> runArguments(const Json& def, const Point& p, const std::string& dir) {
  std::vector<std::string> args = {"run", def["scene"].get<std::string>(), "--out", dir, "--quiet", "--no-frames"};
  if (def["threads"].get<int>() > 0) args.insert(args.end(), {"--threads", std::to_string(def["threads"].get<int>())});
  for (const auto& s : def["set"]) args.insert(args.end(), {"--set", s.get<std::string>()});
  for (std::size_t i = 0; i < p.values.size(); ++i)
    args.insert(args.end(), {"--set", def["vary"][i]["key"].get<std::string>() + "=" + p.values[i]});
  return args;
}



// Runs the given points, `jobs` at a time; each finished point gets its point.json (the exit
// code and the process's wall time), which is what marks it done for a resumed sweep.
void runPoints(const Json& def, const std::string& out, const std::string& executable, const std::vector<long>& todo,
               int jobs) {
  const std::vector<Point> all = points(def);
  std::map<pid_t, std::pair<long, std::chrono::steady_clock::time_point>> running;
  std::size_t next = 0;
  auto finish = [&](pid_t pid, int status) {
    const auto [k, start] = running.at(pid);
    running.erase(pid);
    const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    Json pj = {{"point", k}, {"values", all[k].values}, {"repeat", all[k].repeat}, {"exit_code", exitCodeOf(status)},
               {"process_seconds", wall}};
    writeFileAtomically(pointDir(out, k) + "/point.json", pj.dump(2) + "\n");
    std::fprintf(stderr, "sweep: point %ld done (exit %d, %.2f s)\n", k, exitCodeOf(status), wall);
  };
  while (next < todo.size() || !running.empty()) {
    while (next < todo.size() && static_cast<int>(running.size()) < jobs) {
      const long k = todo[next++];
      const std::string dir = pointDir(out, k);
      fs::remove_all(dir);  // an unfinished earlier attempt starts again
      fs::create_directories(dir);
      const pid_t pid = spawn(executable, runArguments(def, all[k], dir), dir + "/log.txt");
      if (pid < 0) {
        Json pj = {{"point", k}, {"values", all[k].values}, {"repeat", all[k].repeat}, {"exit_code", 127}, {"process_seconds", 0}};
        writeFileAtomically(dir + "/point.json", pj.dump(2) + "\n");
        continue;
      }
      running[pid] = {k, std::chrono::steady_clock::now()};
    }
    if (running.empty()) break;
    int status = 0;
    const pid_t pid = waitpid(-1, &status, 0);
    if (pid > 0 && running.count(pid)) finish(pid, status);
  }
}

// sweep.csv from the points' directories: one row per point that has finished.
int writeTable(const Json& def, const std::string& out) {
  const std::vector<Point> all = points(def);
  std::vector<std::string> checkNames, diagnosticNames;
  std::set<std::string> diagnosticSet;
  std::vector<std::pair<Json, Json>> rows;  // (point.json, summary.json)
  std::size_t missing = 0;
  for (std::size_t k = 0; k < all.size(); ++k) {
    const Json pj = readJson(pointDir(out, k) + "/point.json");
    if (pj.is_null()) {
      ++missing;
      continue;
    }
    const Json sj = readJson(pointDir(out, k) + "/summary.json");
    if (sj.is_object() && sj.contains("checks"))
      for (const auto& c : sj["checks"])
        if (std::find(checkNames.begin(), checkNames.end(), c["name"].get<std::string>()) == checkNames.end())
          checkNames.push_back(c["name"]);
    if (sj.is_object() && sj.contains("final_diagnostics"))
      for (const auto& [name, v] : sj["final_diagnostics"].items())
        if (diagnosticSet.insert(name).second) diagnosticNames.push_back(name);
    rows.emplace_back(pj, sj);
  }
  std::sort(diagnosticNames.begin(), diagnosticNames.end());
  std::ostringstream csv;
  csv << "point";
  for (const auto& v : def["vary"]) csv << ',' << csvField(v["key"].get<std::string>());
  csv << ",repeat,exit_code,status,steps,wall_seconds,us_per_step,state_hash";
  for (const auto& c : checkNames) csv << ",check_" << c << "_value,check_" << c << "_error,check_" << c << "_pass";
  for (const auto& n : diagnosticNames) csv << ",final_" << n;
  csv << '\n';
  for (const auto& [pj, sj] : rows) {
    csv << pj["point"].get<long>();
    for (const auto& v : pj["values"]) csv << ',' << csvField(v.get<std::string>());
    csv << ',' << pj["repeat"].get<int>() << ',' << pj["exit_code"].get<int>();
    if (!sj.is_object()) {  // rejected before running, or crashed: a row without results
      csv << ",failed,0,,,";
      for (std::size_t i = 0; i < checkNames.size() * 3 + diagnosticNames.size(); ++i) csv << ',';
      csv << '\n';
      continue;
    }
    const long steps = sj.value("steps_completed", 0L);
    const double wall = sj.value("total_wall_seconds", 0.0);
    csv << ',' << sj.value("status", std::string()) << ',' << steps << ',' << num(wall) << ','
        << (steps > 0 ? num(wall / steps * 1e6) : std::string()) << ',' << sj.value("state_hash", std::string());
    for (const auto& name : checkNames) {
      Json found;
      if (sj.contains("checks"))
        for (const auto& c : sj["checks"])
          if (c["name"] == name) found = c;
      auto cell = [&](const char* key) {
        return found.is_object() && found[key].is_number() ? num(found[key].get<double>()) : std::string();
      };
      csv << ',' << cell("value") << ',' << cell("error") << ','
          << (found.is_object() ? (found["pass"].get<bool>() ? "1" : "0") : "");
    }
    for (const auto& n : diagnosticNames) {
      const Json& f = sj["final_diagnostics"];
      csv << ',' << (f.contains(n) && f[n].is_number() ? num(f[n].get<double>()) : std::string());
    }
    csv << '\n';
  }
  try {
    writeFileAtomically(out + "/sweep.csv", csv.str());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "monolith: %s\n", e.what());
    return 1;
  }
  std::printf("%s/sweep.csv: %zu rows%s\n", out.c_str(), rows.size(),
              missing ? (", " + std::to_string(missing) + " points not run yet").c_str() : "");
  return 0;
}

int writeSlurm(const Json& def, const SweepOptions& o) {
  const std::size_t n = points(def).size();
  const std::string out = fs::absolute(o.out).string();
  std::ostringstream s;
  s << "#!/bin/bash\n"
    << "# One array task per point of the sweep; collect with: monolith sweep --collect " << shellQuote(out) << "\n"
    << "#SBATCH --job-name=monolith-sweep\n"
    << "#SBATCH --array=0-" << n - 1 << "\n"
    << "#SBATCH --ntasks=1\n"
    << "#SBATCH --cpus-per-task=" << (o.threads > 0 ? o.threads : 1) << "\n"
    << "#SBATCH --output=" << out << "/slurm-%A_%a.log\n"
    << "exec " << shellQuote(fs::absolute(o.executable).string()) << " sweep " << shellQuote(def["scene"]);
  for (const auto& [key, values] : o.vary) {
    std::string joined;
    for (const auto& v : values) joined += (joined.empty() ? "" : ",") + v;
    s << " --vary " << shellQuote(key + "=" + joined);
  }
  for (const auto& [k, v] : o.sets) s << " --set " << shellQuote(k + "=" + v);
  if (o.repeat > 1) s << " --repeat " << o.repeat;
  if (o.threads > 0) s << " --threads " << o.threads;
  s << " --out " << shellQuote(out) << " --point \"$SLURM_ARRAY_TASK_ID\"\n";
  writeFileAtomically(o.out + "/sweep.slurm", s.str());
  std::printf("%s/sweep.slurm: %zu array tasks; submit with sbatch, then monolith sweep --collect %s\n", o.out.c_str(), n,
              o.out.c_str());
  return 0;
}

}  // namespace

int runSweep(const SweepOptions& o) {
  const Json def = definitionOf(o);
  try {
    fs::create_directories(o.out + "/points");
  } catch (const std::exception& e) {
    std::fprintf(stderr, "monolith: cannot create '%s': %s\n", o.out.c_str(), e.what());
    return 1;
  }
  // A directory holds one sweep: resuming with other settings would mix two tables.
  const Json existing = readJson(o.out + "/sweep.json");
  if (!existing.is_null() && existing != def) {
    std::fprintf(stderr, "monolith: %s holds another sweep (%s); use another --out\n", o.out.c_str(),
                 (o.out + "/sweep.json").c_str());
    return 2;
  }
  if (existing.is_null()) writeFileAtomically(o.out + "/sweep.json", def.dump(2) + "\n");
  if (o.emitSlurm) return writeSlurm(def, o);
  const long n = static_cast<long>(points(def).size());
  if (o.point >= n) {
    std::fprintf(stderr, "monolith: --point %ld: the sweep has points 0..%ld\n", o.point, n - 1);
    return 2;
  }
  std::vector<long> todo;
  for (long k = 0; k < n; ++k)
    if ((o.point < 0 || k == o.point) && !fs::exists(pointDir(o.out, k) + "/point.json")) todo.push_back(k);
  std::fprintf(stderr, "sweep: %ld points, %zu to run, %d at a time\n", o.point < 0 ? n : 1L, todo.size(), o.jobs);
  runPoints(def, o.out, o.executable, todo, o.jobs);
  if (o.point >= 0) return 0;  // an array task: the table is built by --collect
  return writeTable(def, o.out);
}

int collectSweep(const std::string& dir) {
  const Json def = readJson(dir + "/sweep.json");
  if (def.is_null()) {
    std::fprintf(stderr, "monolith: --collect %s: no sweep.json (not a sweep directory)\n", dir.c_str());
    return 2;
  }
  return writeTable(def, dir);
}

}  // namespace monolith
