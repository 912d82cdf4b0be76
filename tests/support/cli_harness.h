// Helpers for scenario tests that drive the monolith executable as a child process: a per-test
// scratch directory, running a command with its output captured, and small file/text utilities.
// Shared by the scenario tests so they all run commands the same way.
#pragma once

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <system_error>
#include <vector>

namespace monolith::test {

struct CommandResult {
  int exitCode = -1;  // -1 when the command did not exit normally (e.g. killed by a signal)
  std::string out, err;
};

// Single-quotes s for /bin/sh, so paths and arguments with spaces or quotes pass through intact.
inline std::string shellQuote(const std::string& s) {
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

// The whole file as bytes; empty if it cannot be read (tests then fail on the content).
inline std::string slurp(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// Replaces the file's content with text, byte for byte (binary: no newline translation).
inline void writeFile(const std::filesystem::path& p, const std::string& text) {
  std::ofstream out(p, std::ios::binary | std::ios::trunc);
  out << text;
}

inline std::vector<std::string> lines(const std::string& text) {
  std::vector<std::string> out;
  std::stringstream ss(text);
  for (std::string l; std::getline(ss, l);) out.push_back(l);
  return out;
}

// A fresh directory per test under /tmp/monolith_tests_<pid>, removed afterwards. The "logs"
// subfolder is always created so that logs() can be handed to run() directly.
class TempDir {
 public:
  TempDir() {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    path_ = std::filesystem::temp_directory_path() / ("monolith_tests_" + std::to_string(::getpid())) /
            (std::string(info->test_suite_name()) + "_" + info->name());
    std::filesystem::remove_all(path_);
    std::filesystem::create_directories(path_ / "logs");
  }
  ~TempDir() {
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
    std::filesystem::remove(path_.parent_path(), ec);  // only succeeds once the last test's directory is gone
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;

  const std::filesystem::path& path() const { return path_; }
  // Where run() keeps each command's stdout/stderr (cmdN.out / cmdN.err).
  std::filesystem::path logs() const { return path_ / "logs"; }

 private:
  std::filesystem::path path_;
};

// Runs argv with stdin from /dev/null and stdout/stderr redirected to files in logDir, then reads
// them back. Files rather than pipes: stderr is then not a TTY (as in batch use), and the two
// streams are kept apart. The command is wrapped in `timeout` so that a hang becomes a failure
// (exit 124) instead of blocking the test binary until ctest kills it: a corrupt step count once
// made `resume` loop for ~2^63 steps.
inline CommandResult run(const std::vector<std::string>& argv, const std::filesystem::path& logDir,
                         int timeoutSeconds = 300) {
  static int counter = 0;
  const std::string id = std::to_string(counter++);
  const std::filesystem::path out = logDir / ("cmd" + id + ".out"), err = logDir / ("cmd" + id + ".err");
  std::string cmd = "timeout " + std::to_string(timeoutSeconds);
  for (const auto& a : argv) cmd += " " + shellQuote(a);
  cmd += " </dev/null >" + shellQuote(out.string()) + " 2>" + shellQuote(err.string());
  const int status = std::system(cmd.c_str());
  CommandResult r;
  r.exitCode = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  r.out = slurp(out);
  r.err = slurp(err);
  return r;
}

}  // namespace monolith::test
