#include "scenarios/plugin_search.h"

#include <algorithm>
#include <cctype>
#include <cstdlib>
#include <filesystem>
#include <stdexcept>

#ifndef MONOLITH_PLUGIN_DIR
#error "MONOLITH_PLUGIN_DIR (this build's plugin directory) must be defined by the build"
#endif

namespace monolith {

bool isPluginName(const std::string& s) {
  if (s.empty()) return false;
  for (char c : s)
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-')) return false;
  return true;
}

std::vector<std::string> pluginSearchPath() {
  std::vector<std::string> dirs;
  if (const char* env = std::getenv("MONOLITH_PLUGIN_PATH")) {
    const std::string list = env;
    std::size_t start = 0;
    while (start <= list.size()) {
      const std::size_t colon = std::min(list.find(':', start), list.size());
      if (colon > start) dirs.push_back(list.substr(start, colon - start));  // empty entries skipped
      start = colon + 1;
    }
  }
  dirs.push_back(MONOLITH_PLUGIN_DIR);
  return dirs;
}

std::string findPlugin(const std::string& name) {
  const std::vector<std::string> dirs = pluginSearchPath();
  std::string searched;
  for (const auto& dir : dirs) {
    const std::filesystem::path candidate = std::filesystem::path(dir) / (name + ".so");
    std::error_code ec;
    if (std::filesystem::is_regular_file(candidate, ec)) return candidate.string();
    searched += (searched.empty() ? "" : ", ") + dir;
  }
  throw std::runtime_error("no plugin " + name + ".so in " + searched +
                           " (add its directory to MONOLITH_PLUGIN_PATH, or give the plugin's path)");
}

}  // namespace monolith
