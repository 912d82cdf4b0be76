#pragma once
// World<d>: the entities of one scene, their component pools and the scene-wide resources.
// Pools are keyed by the component's stable name (T::kName) rather than by C++ type
// identity, so a plugin built as a separate shared object finds the same pool.
#include <Eigen/Core>
#include <map>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <tuple>
#include <unordered_map>
#include <vector>

#include "ecs/component_pool.h"
#include "ecs/entity.h"

namespace monolith {

template <int d>
using Vec = Eigen::Matrix<double, d, 1>;

// Scene-wide physical settings shared by systems (read-only during a step). The settings of one
// group of systems (contact, fluid, the rigid rotation rule) are resources instead
// (World::resource), declared next to the solvers they steer.
template <int d>
struct WorldSettings {
  Vec<d> gravity = Vec<d>::Zero();
};

// A scene-wide value of a type the world knows nothing of (a solver's settings): stored under
// the type's stable name T::kName, as components are, so a plugin finds the same one.
class ResourceBase {
 public:
  virtual ~ResourceBase() = default;
};
template <class T>
class Resource final : public ResourceBase {
 public:
  T value;
};

template <int d>
class World {
  static_assert(d == 2 || d == 3, "Monolith simulates in 2 or 3 dimensions");

 public:
  static constexpr int dimension = d;

  Entity create(const std::string& name = "") {
    const Entity e = entities_.create();
    if (e.index >= names_.size()) names_.resize(e.index + 1);
    names_[e.index] = name;
    if (!name.empty()) byName_[name] = e;
    return e;
  }

  void destroy(Entity e) {
    if (!entities_.alive(e)) return;
    for (auto& [_, pool] : pools_) pool->remove(e);
    if (!names_[e.index].empty()) byName_.erase(names_[e.index]);
    names_[e.index].clear();
    entities_.destroy(e);
  }

  bool alive(Entity e) const { return entities_.alive(e); }
  std::size_t entityCount() const { return entities_.aliveCount(); }
  const EntityRegistry& entityRegistry() const { return entities_; }

  const std::string& name(Entity e) const {
    static const std::string none;
    return e.index < names_.size() ? names_[e.index] : none;
  }
  // A human-readable label for messages: the name, else "#index".
  std::string label(Entity e) const {
    const auto& n = name(e);
    return n.empty() ? "#" + std::to_string(e.index) : "'" + n + "' (#" + std::to_string(e.index) + ")";
  }
  std::optional<Entity> find(const std::string& name) const {
    auto it = byName_.find(name);
    if (it == byName_.end()) return std::nullopt;
    return it->second;
  }

  template <class T>
  Pool<T>& pool() {
    auto it = pools_.find(T::kName);
    if (it == pools_.end()) it = pools_.emplace(T::kName, std::make_unique<Pool<T>>(T::kName)).first;
    auto* typed = dynamic_cast<Pool<T>*>(it->second.get());
    if (!typed) throw std::logic_error(std::string("component name clash: ") + T::kName);
    return *typed;
  }
  // Null when no component of type T was ever added: lets systems report needed() == false.
  template <class T>
  const Pool<T>* findPool() const {
    auto it = pools_.find(T::kName);
    return it == pools_.end() ? nullptr : dynamic_cast<const Pool<T>*>(it->second.get());
  }
  template <class T>
  std::size_t count() const {
    const auto* p = findPool<T>();
    return p ? p->size() : 0;
  }
  bool hasComponentNamed(const std::string& name) const {
    auto it = pools_.find(name);
    return it != pools_.end() && it->second->size() > 0;
  }

  template <class T>
  T& add(Entity e, T value = T{}) {
    if (!alive(e)) throw std::logic_error("World::add on a dead entity");
    return pool<T>().add(e, std::move(value));
  }
  template <class T>
  T* get(Entity e) {
    auto it = pools_.find(T::kName);
    return it == pools_.end() ? nullptr : static_cast<Pool<T>*>(it->second.get())->get(e);
  }
  template <class T>
  const T* get(Entity e) const {
    auto it = pools_.find(T::kName);
    return it == pools_.end() ? nullptr : static_cast<const Pool<T>*>(it->second.get())->get(e);
  }
  template <class T>
  bool has(Entity e) const {
    return get<T>(e) != nullptr;
  }
  template <class T>
  void remove(Entity e) {
    auto it = pools_.find(T::kName);
    if (it != pools_.end()) it->second->remove(e);
  }

  // Calls f(entity, A&, B&...) for every entity that has all of A, B, ..., in the dense order
  // of A's pool (deterministic).
  template <class A, class... B, class F>
  void each(F&& f) {
    auto& first = pool<A>();
    auto rest = std::forward_as_tuple(pool<B>()...);
    for (std::size_t i = 0; i < first.size(); ++i) {
      const Entity e = first.entities()[i];
      auto others = std::apply([&](auto&... p) { return std::make_tuple(p.get(e)...); }, rest);
      const bool all = std::apply([](auto*... p) { return (true && ... && (p != nullptr)); }, others);
      if (all) std::apply([&](auto*... p) { f(e, first.components()[i], *p...); }, others);
    }
  }

  const std::map<std::string, std::unique_ptr<PoolBase>>& pools() const { return pools_; }
  // Registers an empty pool for a type (used when restoring a checkpoint).
  template <class T>
  void ensurePool() {
    pool<T>();
  }
  PoolBase* poolNamed(const std::string& name) {
    auto it = pools_.find(name);
    return it == pools_.end() ? nullptr : it->second.get();
  }

  WorldSettings<d>& settings() { return settings_; }
  const WorldSettings<d>& settings() const { return settings_; }

  // The resource of type T, or T's defaults when none was set (read-only: systems of one stage
  // may read at once).
  template <class T>
  const T& resource() const {
    auto it = resources_.find(T::kName);
    if (it != resources_.end())
      if (const auto* typed = dynamic_cast<const Resource<T>*>(it->second.get())) return typed->value;
    static const T defaults{};
    return defaults;
  }
  // The resource of type T to change (the scene parser, tests), created with T's defaults; not
  // during a step.
  template <class T>
  T& mutableResource() {
    auto it = resources_.find(T::kName);
    if (it == resources_.end()) it = resources_.emplace(T::kName, std::make_unique<Resource<T>>()).first;
    auto* typed = dynamic_cast<Resource<T>*>(it->second.get());
    if (!typed) throw std::logic_error(std::string("resource name clash: ") + T::kName);
    return typed->value;
  }

  // Raw entity table for checkpoints.
  EntityRegistry& entityRegistryMutable() { return entities_; }
  std::vector<std::string>& namesMutable() { return names_; }
  void rebuildNameIndex() {
    byName_.clear();
    for (std::uint32_t i = 0; i < names_.size(); ++i) {
      const Entity e = entities_.atSlot(i);
      if (e.valid() && !names_[i].empty()) byName_[names_[i]] = e;
    }
  }

 private:
  EntityRegistry entities_;
  std::vector<std::string> names_;
  std::unordered_map<std::string, Entity> byName_;
  std::map<std::string, std::unique_ptr<PoolBase>> pools_;  // ordered: checkpoints are deterministic
  WorldSettings<d> settings_;
  std::map<std::string, std::unique_ptr<ResourceBase>> resources_;
};

}  // namespace monolith
