// Test plugin that claims a different ABI version: the loader must refuse it before calling
// its registration function.
#include "ecs/plugin.h"

extern "C" const monolith::PluginAbi* monolith_plugin_abi() {
  static monolith::PluginAbi abi = [] {
    monolith::PluginAbi a = monolith::currentPluginAbi();
    a.abiVersion = monolith::kPluginAbiVersion + 98;
    return a;
  }();
  return &abi;
}

extern "C" int monolith_plugin_register(monolith::Registry*) { return 0; }
