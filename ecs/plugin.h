#pragma once
// Plugins: shared libraries exporting two C functions,
//   const monolith::PluginAbi* monolith_plugin_abi(void);
//   int monolith_plugin_register(monolith::Registry* registry);   // 0 = success
// The loader compares the plugin's ABI record with its own before calling anything else, so a
// plugin built against another Monolith version or with layout-changing flags is refused with
// a message naming what differs. Define the first with MONOLITH_PLUGIN_ABI().
#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "ecs/registry.h"

namespace monolith {

// Bump whenever a type crossing the plugin boundary changes layout or meaning.
inline constexpr std::uint32_t kPluginAbiVersion = 9;

struct PluginAbi {
  std::uint32_t abiVersion;
  std::uint32_t sizeofRegistry;
  std::uint32_t sizeofStepContext;
  std::uint32_t eigenVersion;  // world*10000 + major*100 + minor
  std::uint32_t eigenMaxAlignBytes;
  std::uint32_t cxxStandard;   // __cplusplus / 100
  std::uint32_t debugBuild;    // NDEBUG absent
};

inline PluginAbi currentPluginAbi() {
  return PluginAbi{kPluginAbiVersion,
                   static_cast<std::uint32_t>(sizeof(Registry)),
                   static_cast<std::uint32_t>(sizeof(StepContext)),
                   static_cast<std::uint32_t>(EIGEN_WORLD_VERSION * 10000 + EIGEN_MAJOR_VERSION * 100 + EIGEN_MINOR_VERSION),
                   static_cast<std::uint32_t>(EIGEN_MAX_ALIGN_BYTES),
                   static_cast<std::uint32_t>(__cplusplus / 100),
#ifdef NDEBUG
                   0u
#else
                   1u
#endif
  };
}

// Names every field that differs ("" when compatible).
std::string describeAbiMismatch(const PluginAbi& host, const PluginAbi& plugin);

struct LoadedPlugin {
  std::string path;
  void* handle = nullptr;
};

class PluginError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// dlopen()s the library, checks its ABI and lets it register. Throws PluginError with the
// path and the reason. Loading the same path twice is a no-op.
class PluginLoader {
 public:
  const LoadedPlugin& load(const std::string& path, Registry& registry);
  const std::vector<LoadedPlugin>& loaded() const { return loaded_; }

 private:
  std::vector<LoadedPlugin> loaded_;
};

}  // namespace monolith

#define MONOLITH_PLUGIN_ABI()                                              \
  extern "C" const monolith::PluginAbi* monolith_plugin_abi() {            \
    static const monolith::PluginAbi abi = monolith::currentPluginAbi();   \
    return &abi;                                                           \
  }
