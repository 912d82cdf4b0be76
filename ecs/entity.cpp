#include "ecs/entity.h"

#include <stdexcept>

namespace monolith {

Entity EntityRegistry::create() {
  ++aliveCount_;
  if (!free_.empty()) {
    const std::uint32_t index = free_.back();
    free_.pop_back();
    alive_[index] = 1;
    return {index, generations_[index]};
  }
  if (generations_.size() >= UINT32_MAX - 1) throw std::length_error("EntityRegistry: out of entity slots");
  generations_.push_back(0);
  alive_.push_back(1);
  return {static_cast<std::uint32_t>(generations_.size() - 1), 0};
}

void EntityRegistry::destroy(Entity e) {
  if (!alive(e)) return;
  alive_[e.index] = 0;
  ++generations_[e.index];  // invalidates every outstanding handle to this slot
  free_.push_back(e.index);
  --aliveCount_;
}

Entity EntityRegistry::atSlot(std::uint32_t index) const {
  if (index >= generations_.size() || !alive_[index]) return {};
  return {index, generations_[index]};
}

void EntityRegistry::restore(std::vector<std::uint32_t> generations, std::vector<std::uint8_t> alive,
                             std::vector<std::uint32_t> freeList) {
  if (generations.size() != alive.size()) throw std::invalid_argument("EntityRegistry::restore: size mismatch");
  generations_ = std::move(generations);
  alive_ = std::move(alive);
  free_ = std::move(freeList);
  aliveCount_ = 0;
  for (auto a : alive_) aliveCount_ += a ? 1 : 0;
}

}  // namespace monolith
