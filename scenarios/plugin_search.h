#pragma once
// Where a plugin named in a scene (or with --plugin) is found. A scene names a plugin either by
// path ("../plugins/my.so", relative to the scene file) or by bare name ("wind_drag"). A name
// is looked up as NAME.so in each directory of the MONOLITH_PLUGIN_PATH environment variable
// (':'-separated, in order), then in this build's own plugin directory. So a shipped scene
// loads the plugin built with the same monolith, whatever the build directory is called, and
// a Debug monolith never picks up a Release plugin by accident (the ABI check would refuse it).
#include <string>
#include <vector>

namespace monolith {

// True for a bare plugin name: letters, digits, '_' and '-' only (no '/', no ".so").
bool isPluginName(const std::string& s);

// The directories searched for a named plugin, in order.
std::vector<std::string> pluginSearchPath();

// NAME.so in the first directory of pluginSearchPath() that has it; std::runtime_error listing
// the directories searched when none has.
std::string findPlugin(const std::string& name);

}  // namespace monolith
