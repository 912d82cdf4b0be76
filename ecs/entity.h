#pragma once
// Entity handles: a 32-bit slot index plus a 32-bit generation. Destroying an entity bumps the
// generation of its slot, so stale handles (e.g. to a fractured body) are detected instead of
// silently aliasing the body that later reuses the slot (DESIGN.md §3).
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace monolith {

struct Entity {
  std::uint32_t index = UINT32_MAX;
  std::uint32_t generation = 0;
  bool valid() const { return index != UINT32_MAX; }
  friend bool operator==(Entity a, Entity b) { return a.index == b.index && a.generation == b.generation; }
  friend bool operator!=(Entity a, Entity b) { return !(a == b); }
  friend bool operator<(Entity a, Entity b) { return a.index < b.index || (a.index == b.index && a.generation < b.generation); }
};

// Owns the slot table. Freed slots are reused in LIFO order; the order is part of the
// deterministic state and is serialized with checkpoints.
class EntityRegistry {
 public:
  Entity create();
  void destroy(Entity e);  // no-op on a dead handle
  bool alive(Entity e) const {
    return e.index < generations_.size() && generations_[e.index] == e.generation && alive_[e.index];
  }
  std::size_t slotCount() const { return generations_.size(); }
  std::size_t aliveCount() const { return aliveCount_; }
  // Handle currently living in a slot (invalid if the slot is free).
  Entity atSlot(std::uint32_t index) const;

  // Raw state for checkpoints.
  const std::vector<std::uint32_t>& generations() const { return generations_; }
  const std::vector<std::uint8_t>& aliveFlags() const { return alive_; }
  const std::vector<std::uint32_t>& freeList() const { return free_; }
  void restore(std::vector<std::uint32_t> generations, std::vector<std::uint8_t> alive, std::vector<std::uint32_t> freeList);

 private:
  std::vector<std::uint32_t> generations_;
  std::vector<std::uint8_t> alive_;
  std::vector<std::uint32_t> free_;
  std::size_t aliveCount_ = 0;
};

}  // namespace monolith

template <>
struct std::hash<monolith::Entity> {
  std::size_t operator()(monolith::Entity e) const noexcept {
    return std::hash<std::uint64_t>()((std::uint64_t(e.generation) << 32) | e.index);
  }
};
