#include "ecs/plugin.h"

#include <dlfcn.h>
#include <sys/stat.h>

#include <sstream>

namespace monolith {

std::string describeAbiMismatch(const PluginAbi& host, const PluginAbi& plugin) {
  std::ostringstream out;
  auto field = [&](const char* name, std::uint32_t h, std::uint32_t p) {
    if (h != p) out << (out.tellp() > 0 ? "; " : "") << name << " is " << p << " in the plugin but " << h << " in monolith";
  };
  field("ABI version", host.abiVersion, plugin.abiVersion);
  if (host.abiVersion == plugin.abiVersion) {  // other fields are only comparable within one ABI version
    field("sizeof(Registry)", host.sizeofRegistry, plugin.sizeofRegistry);
    field("sizeof(StepContext)", host.sizeofStepContext, plugin.sizeofStepContext);
    field("Eigen version", host.eigenVersion, plugin.eigenVersion);
    field("EIGEN_MAX_ALIGN_BYTES", host.eigenMaxAlignBytes, plugin.eigenMaxAlignBytes);
    field("C++ standard", host.cxxStandard, plugin.cxxStandard);
    field("debug build (no NDEBUG)", host.debugBuild, plugin.debugBuild);
  }
  return out.str();
}

const LoadedPlugin& PluginLoader::load(const std::string& path, Registry& registry) {
  for (const auto& p : loaded_)
    if (p.path == path) return p;
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) throw PluginError("plugin '" + path + "': file not found");
  void* handle = ::dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
  if (!handle) throw PluginError("plugin '" + path + "': cannot be loaded: " + std::string(::dlerror()));
  using AbiFn = const PluginAbi* (*)();
  using RegisterFn = int (*)(Registry*);
  auto abiFn = reinterpret_cast<AbiFn>(::dlsym(handle, "monolith_plugin_abi"));
  auto registerFn = reinterpret_cast<RegisterFn>(::dlsym(handle, "monolith_plugin_register"));
  if (!abiFn || !registerFn) {
    ::dlclose(handle);
    throw PluginError("plugin '" + path +
                      "': not a Monolith plugin (it must export monolith_plugin_abi and monolith_plugin_register)");
  }
  const std::string mismatch = describeAbiMismatch(currentPluginAbi(), *abiFn());
  if (!mismatch.empty()) {
    ::dlclose(handle);
    throw PluginError("plugin '" + path + "': ABI mismatch: " + mismatch + "; rebuild the plugin against this monolith");
  }
  registry.setOrigin("plugin " + path);
  const int status = registerFn(&registry);
  registry.setOrigin("built-in");
  if (status != 0) throw PluginError("plugin '" + path + "': registration failed with code " + std::to_string(status));
  // The handle stays open for the life of the process: registered factories point into it.
  loaded_.push_back(LoadedPlugin{path, handle});
  return loaded_.back();
}

}  // namespace monolith
