#pragma once
// Checkpoints: the full state of a run in a versioned binary file, written atomically
// (temporary file + rename), so a crash never leaves a half-written checkpoint behind.
//
// Layout (format 4): magic "MONOLITH-CKPT", u32 format, u32 endianness probe 0x01020304,
// u32 sizeof(double), i32 dimension, i64 step (steps completed), f64 time, string scene file,
// string scene JSON (after --set overrides), i64 checkpoint interval of the run, i64 + f64 the
// clock origin of a fixed-dt run (ClockOrigin), the field layout of every saved component
// (u64 count, then name and PoolBase::fieldLayout() strings), world state (see serializeWorld),
// u64 FNV-1a of every byte before it (a flipped bit anywhere is caught).
// A component whose fields differ from the saved layout is refused by name: its bytes would
// otherwise be read into the wrong fields. Formats 2 and 3 (no layouts; format 2 also without
// the clock origin, then always (0, 0)) are still read for the components whose fields have not
// changed since (rigid bodies, shapes, colliders, kinematic motion, forces, MAC grids and
// obstacles); files holding any other component are refused.
#include <cstdint>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "ecs/registry.h"
#include "ecs/world.h"
#include "scenarios/scene.h"

namespace monolith {

inline constexpr std::uint32_t kCheckpointFormat = 4;

// Entity table (generations, alive flags, free list, names) and every pool, in name order.
template <int d>
void serializeWorld(const World<d>& world, BinaryWriter& out);
// Replaces the world's state with the serialized one. Pools are created through the registry
// (so plugin components restore too); an unknown component name is an error. `beforePool`, if
// given, sees each component name before its pool is read (and may refuse it by throwing).
template <int d>
void deserializeWorld(World<d>& world, BinaryReader& in, const Registry& registry,
                      const std::function<void(const std::string&)>& beforePool = {});

// FNV-1a hash of serializeWorld's bytes: equal hashes = bitwise equal state.
template <int d>
std::uint64_t stateHash(const World<d>& world);

struct CheckpointHeader {
  int dimension = 3;
  long step = 0;  // steps completed
  double time = 0;
  std::string sceneFile;
  std::string sceneJson;
  long checkpointEvery = 0;  // the run's interval, kept by `monolith resume`
  ClockOrigin clock;         // the run's, so that a resume continues its clock bitwise
};

template <int d>
void writeCheckpoint(const std::string& path, const CheckpointHeader& header, const World<d>& world);

// Reads the header and keeps the rest for restoreCheckpointWorld().
struct CheckpointFile {
  std::string path;
  std::uint32_t format = 0;
  CheckpointHeader header;
  std::vector<std::pair<std::string, std::string>> layouts;  // component name, field layout (format >= 4)
  std::vector<std::uint8_t> bytes;
  std::size_t worldOffset = 0, worldEnd = 0;
};
CheckpointFile readCheckpoint(const std::string& path);
template <int d>
void restoreCheckpointWorld(const CheckpointFile& file, World<d>& world, const Registry& registry);

}  // namespace monolith
