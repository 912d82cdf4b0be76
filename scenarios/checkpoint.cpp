#include "scenarios/checkpoint.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <stdexcept>

#include "scenarios/vtk_writer.h"

namespace monolith {

namespace {
constexpr char kMagic[] = "MONOLITH-CKPT";
constexpr std::uint32_t kEndianProbe = 0x01020304u;
}  // namespace

template <int d>
void serializeWorld(const World<d>& world, BinaryWriter& out) {
  const EntityRegistry& entities = world.entityRegistry();
  out.vector(entities.generations());
  out.vector(entities.aliveFlags());
  out.vector(entities.freeList());
  out.pod<std::uint64_t>(entities.slotCount());
  for (std::uint32_t i = 0; i < entities.slotCount(); ++i) out.string(world.name(Entity{i, 0}));
  std::uint64_t nonEmpty = 0;
  for (const auto& [name, pool] : world.pools()) nonEmpty += pool->size() > 0 ? 1 : 0;
  out.pod(nonEmpty);
  for (const auto& [name, pool] : world.pools()) {
    if (pool->size() == 0) continue;  // an empty pool and a missing one are the same state
    out.string(name);
    pool->serialize(out);
  }
}

template <int d>
void deserializeWorld(World<d>& world, BinaryReader& in, const Registry& registry,
                      const std::function<void(const std::string&)>& beforePool) {
  auto generations = in.vector<std::uint32_t>();
  auto alive = in.vector<std::uint8_t>();
  auto freeList = in.vector<std::uint32_t>();
  const auto slots = in.pod<std::uint64_t>();
  if (slots != generations.size() || alive.size() != generations.size()) in.fail("entity table sizes differ");
  // A free-list slot out of range or alive would corrupt the next World::create().
  for (const std::uint32_t i : freeList)
    if (i >= slots || alive[i]) in.fail("entity free list names slot " + std::to_string(i) + " that is not a free slot");
  std::vector<std::string> names(slots);
  for (auto& n : names) n = in.string();
  world.entityRegistryMutable().restore(std::move(generations), std::move(alive), std::move(freeList));
  world.namesMutable() = std::move(names);
  world.rebuildNameIndex();
  for (const auto& [name, pool] : world.pools()) pool->clear();
  const auto poolCount = in.pod<std::uint64_t>();
  for (std::uint64_t k = 0; k < poolCount; ++k) {
    const std::string name = in.string();
    if (beforePool) beforePool(name);
    const auto* type = registry.findComponent<d>(name);
    if (!type)
      throw std::runtime_error("checkpoint holds component '" + name +
                               "' that no built-in type or loaded plugin provides (load the plugin the run used)");
    type->ensurePool(world);
    PoolBase* pool = world.poolNamed(name);
    pool->deserialize(in, world.entityRegistry().slotCount());
    // Corrupt handles would otherwise pass silently and later index the entity table out of
    // range: every component must belong to a live entity of the restored table.
    const EntityRegistry& table = world.entityRegistry();
    for (const Entity e : pool->entities())
      if (!table.alive(e))
        in.fail("component '" + name + "' of entity #" + std::to_string(e.index) + " (generation " +
                std::to_string(e.generation) + ") that is not alive in the entity table");
  }
}

template <int d>
std::uint64_t stateHash(const World<d>& world) {
  BinaryWriter out;
  serializeWorld(world, out);
  return fnv1a(out.bytes().data(), out.bytes().size());
}

template <int d>
void writeCheckpoint(const std::string& path, const CheckpointHeader& header, const World<d>& world) {
  BinaryWriter out;
  out.raw(kMagic, sizeof kMagic);
  out.pod(kCheckpointFormat);
  out.pod(kEndianProbe);
  out.pod<std::uint32_t>(sizeof(double));
  out.pod<std::int32_t>(d);
  out.pod<std::int64_t>(header.step);
  out.pod(header.time);
  out.string(header.sceneFile);
  out.string(header.sceneJson);
  out.pod<std::int64_t>(header.checkpointEvery);
  out.pod<std::int64_t>(header.clock.step);
  out.pod(header.clock.time);
  std::uint64_t saved = 0;
  for (const auto& [name, pool] : world.pools()) saved += pool->size() > 0 ? 1 : 0;
  out.pod(saved);
  for (const auto& [name, pool] : world.pools()) {
    if (pool->size() == 0) continue;
    out.string(name);
    out.string(pool->fieldLayout());
  }
  serializeWorld(world, out);
  out.pod(fnv1a(out.bytes().data(), out.bytes().size()));
  writeFileAtomically(path, std::string(out.bytes().begin(), out.bytes().end()));
}

CheckpointFile readCheckpoint(const std::string& path) {
  // An ifstream opens a directory and then fails deep in the read: say what it is.
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec))
    throw std::runtime_error("checkpoint '" + path + "': a directory, not a checkpoint file");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error("checkpoint '" + path + "': no such file or it cannot be read");
  CheckpointFile f;
  f.path = path;
  f.bytes.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  BinaryReader r(f.bytes.data(), f.bytes.size(), "checkpoint '" + path + "'");
  char magic[sizeof kMagic];
  if (f.bytes.size() < sizeof kMagic) r.fail("file too short to be a checkpoint");
  r.raw(magic, sizeof magic);
  if (std::memcmp(magic, kMagic, sizeof kMagic) != 0) r.fail("not a Monolith checkpoint (bad magic)");
  const auto format = r.pod<std::uint32_t>();
  f.format = format;
  constexpr std::uint32_t kOldestFormat = 2;
  if (format < kOldestFormat || format > kCheckpointFormat)
    throw std::runtime_error("checkpoint '" + path + "': format " + std::to_string(format) + ", this monolith reads formats " +
                             std::to_string(kOldestFormat) + " to " + std::to_string(kCheckpointFormat));
  constexpr std::size_t kChecksumBytes = sizeof(std::uint64_t);
  if (f.bytes.size() < sizeof kMagic + 4 + kChecksumBytes) r.fail("file too short to be a checkpoint");
  std::uint64_t stored = 0;
  std::memcpy(&stored, f.bytes.data() + f.bytes.size() - kChecksumBytes, kChecksumBytes);
  if (fnv1a(f.bytes.data(), f.bytes.size() - kChecksumBytes) != stored)
    throw std::runtime_error("checkpoint '" + path + "': checksum mismatch: the file is corrupted or truncated");
  f.worldEnd = f.bytes.size() - kChecksumBytes;
  if (r.pod<std::uint32_t>() != kEndianProbe || r.pod<std::uint32_t>() != sizeof(double))
    throw std::runtime_error("checkpoint '" + path + "': written on a machine with another byte order or double size");
  f.header.dimension = r.pod<std::int32_t>();
  f.header.step = static_cast<long>(r.pod<std::int64_t>());
  // A corrupt (negative) step would make the resumed loop run ~2^63 steps instead of failing.
  if (f.header.step < 0) r.fail("negative step count " + std::to_string(f.header.step));
  f.header.time = r.pod<double>();
  f.header.sceneFile = r.string();
  f.header.sceneJson = r.string();
  f.header.checkpointEvery = static_cast<long>(r.pod<std::int64_t>());
  if (f.header.checkpointEvery < 0) r.fail("negative checkpoint interval");
  if (format >= 3) {
    f.header.clock.step = static_cast<long>(r.pod<std::int64_t>());
    f.header.clock.time = r.pod<double>();
    if (f.header.clock.step < 0 || f.header.clock.step > f.header.step || !std::isfinite(f.header.clock.time))
      r.fail("clock origin (step " + std::to_string(f.header.clock.step) + ") is not a step of the run before this one");
  }
  if (format >= 4) {
    const auto count = r.pod<std::uint64_t>();
    if (count > r.remaining()) r.fail("component layout table longer than the file");
    for (std::uint64_t k = 0; k < count; ++k) {
      std::string name = r.string();
      f.layouts.emplace_back(std::move(name), r.string());
    }
  }
  if (f.header.dimension != 2 && f.header.dimension != 3) r.fail("dimension is not 2 or 3");
  f.worldOffset = f.bytes.size() - r.remaining();
  if (f.worldOffset > f.worldEnd) r.fail("header runs into the checksum");
  return f;
}

namespace {

// Built-in components whose saved fields changed after format 3 (or that did not exist then):
// a format 2 or 3 file holding one of them was written with another layout.
bool changedSinceFormat3(const std::string& name) {
  static const char* const kNames[] = {"particles",      "simplex_mesh", "elasticity", "rigid_binding",
                                       "two_phase_flow", "sleep",        "fluid_coupling", "fsi_solver",
                                       "joint",          "articulation", "spring_mount", "level_set"};
  for (const char* n : kNames)
    if (name == n) return true;
  return false;
}

// "a b c" -> {a, b, c}: the fields of one layout, to name what differs.
std::vector<std::string> layoutFields(const std::string& layout) {
  std::vector<std::string> fields;
  std::size_t start = 0;
  while (start < layout.size()) {
    const std::size_t end = std::min(layout.find(' ', start), layout.size());
    fields.push_back(layout.substr(start, end - start));
    start = end + 1;
  }
  return fields;
}

std::string joinMissing(const std::vector<std::string>& from, const std::vector<std::string>& in) {
  std::string out;
  for (const auto& f : from)
    if (std::find(in.begin(), in.end(), f) == in.end()) out += (out.empty() ? "" : ", ") + f;
  return out.empty() ? "none" : out;
}

template <int d>
void checkLayouts(const CheckpointFile& file, World<d>& world, const Registry& registry) {
  for (const auto& [name, saved] : file.layouts) {
    const auto* type = registry.findComponent<d>(name);
    if (!type) continue;  // deserializeWorld names the missing type
    type->ensurePool(world);
    const std::string current = world.poolNamed(name)->fieldLayout();
    if (current == saved) continue;
    const auto savedFields = layoutFields(saved), currentFields = layoutFields(current);
    throw std::runtime_error("checkpoint '" + file.path + "': component '" + name +
                             "' was saved with other fields than this monolith's (only in the file: " +
                             joinMissing(savedFields, currentFields) + "; only here: " +
                             joinMissing(currentFields, savedFields) +
                             "); it was written by another version: run the scene again from its start");
  }
}

}  // namespace

template <int d>
void restoreCheckpointWorld(const CheckpointFile& file, World<d>& world, const Registry& registry) {
  BinaryReader r(file.bytes.data() + file.worldOffset, file.worldEnd - file.worldOffset, "checkpoint world state");
  checkLayouts(file, world, registry);
  const auto refuseOld = [&](const std::string& name) {
    if (file.format < 4 && changedSinceFormat3(name))
      throw std::runtime_error("checkpoint '" + file.path + "': format " + std::to_string(file.format) +
                               " file holds component '" + name +
                               "', whose saved fields have changed since that format; run the scene again from its start");
  };
  deserializeWorld(world, r, registry, refuseOld);
  if (!r.atEnd()) r.fail("trailing bytes after the world state");
}

template void serializeWorld<2>(const World<2>&, BinaryWriter&);
template void serializeWorld<3>(const World<3>&, BinaryWriter&);
template void deserializeWorld<2>(World<2>&, BinaryReader&, const Registry&,
                                  const std::function<void(const std::string&)>&);
template void deserializeWorld<3>(World<3>&, BinaryReader&, const Registry&,
                                  const std::function<void(const std::string&)>&);
template std::uint64_t stateHash<2>(const World<2>&);
template std::uint64_t stateHash<3>(const World<3>&);
template void writeCheckpoint<2>(const std::string&, const CheckpointHeader&, const World<2>&);
template void writeCheckpoint<3>(const std::string&, const CheckpointHeader&, const World<3>&);
template void restoreCheckpointWorld<2>(const CheckpointFile&, World<2>&, const Registry&);
template void restoreCheckpointWorld<3>(const CheckpointFile&, World<3>&, const Registry&);

}  // namespace monolith
