#pragma once
// Checkpoints: the full state of a run in a versioned binary file, written atomically
// (temporary file + rename), so a crash never leaves a half-written checkpoint behind.
//
// Layout (format 3): magic "MONOLITH-CKPT", u32 format, u32 endianness probe 0x01020304,
// u32 sizeof(double), i32 dimension, i64 step (steps completed), f64 time, string scene file,
// string scene JSON (after --set overrides), i64 checkpoint interval of the run, i64 + f64 the
// clock origin of a fixed-dt run (ClockOrigin), world state (see serializeWorld), u64 FNV-1a of
// every byte before it (a flipped bit anywhere is caught). Format 2, without the clock origin
// (which was then always (0, 0)), is still read.
#include <cstdint>
#include <string>
#include <vector>

#include "ecs/registry.h"
#include "ecs/world.h"
#include "scenarios/scene.h"

namespace monolith {

inline constexpr std::uint32_t kCheckpointFormat = 3;

// Entity table (generations, alive flags, free list, names) and every pool, in name order.
template <int d>
void serializeWorld(const World<d>& world, BinaryWriter& out);
// Replaces the world's state with the serialized one. Pools are created through the registry
// (so plugin components restore too); an unknown component name is an error.
template <int d>
void deserializeWorld(World<d>& world, BinaryReader& in, const Registry& registry);

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
  CheckpointHeader header;
  std::vector<std::uint8_t> bytes;
  std::size_t worldOffset = 0, worldEnd = 0;
};
CheckpointFile readCheckpoint(const std::string& path);
template <int d>
void restoreCheckpointWorld(const CheckpointFile& file, World<d>& world, const Registry& registry);

}  // namespace monolith
