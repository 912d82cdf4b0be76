#pragma once
// One pool per component type: a sparse set. Components of a type live densely in insertion
// order (iteration is cache-friendly and deterministic); `sparse_` maps an entity slot to its
// dense position. Removal swaps with the last element, which keeps the order deterministic.
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <type_traits>
#include <vector>

#include "ecs/entity.h"
#include "ecs/fields.h"

namespace monolith {

struct ComponentViolation {
  Entity entity;
  std::string component;
  FieldViolation field;
};

// Type-erased interface: what the world needs from any pool (destroying entities, checkpoints,
// the blow-up guard), without knowing the component type.
class PoolBase {
 public:
  virtual ~PoolBase() = default;
  virtual const std::string& componentName() const = 0;
  virtual std::size_t size() const = 0;
  virtual const std::vector<Entity>& entities() const = 0;
  virtual bool contains(Entity e) const = 0;
  virtual void remove(Entity e) = 0;
  virtual void clear() = 0;
  virtual void serialize(BinaryWriter& out) const = 0;
  // Reads components written by serialize() (replacing the pool's content). Entity indices
  // must be below `slotCount` (the restored entity table): a corrupt index must not make the
  // sparse table allocate gigabytes.
  virtual void deserialize(BinaryReader& in, std::size_t slotCount) = 0;
  virtual std::optional<ComponentViolation> firstViolation(double maxAbs) const = 0;
  // The saved layout of one component (FieldLayoutWriter).
  virtual std::string fieldLayout() const = 0;
};

template <class T, class = void>
struct HasAfterLoad : std::false_type {};
template <class T>
struct HasAfterLoad<T, std::void_t<decltype(std::declval<T&>().afterLoad())>> : std::true_type {};

template <class T>
class Pool final : public PoolBase {
 public:
  static constexpr std::uint32_t kAbsent = UINT32_MAX;

  explicit Pool(std::string name) : name_(std::move(name)) {}

  const std::string& componentName() const override { return name_; }
  std::size_t size() const override { return dense_.size(); }
  const std::vector<Entity>& entities() const override { return entities_; }
  bool contains(Entity e) const override {
    return e.index < sparse_.size() && sparse_[e.index] != kAbsent && entities_[sparse_[e.index]] == e;
  }

  T& add(Entity e, T value) {
    if (contains(e)) {
      dense_[sparse_[e.index]] = std::move(value);
      return dense_[sparse_[e.index]];
    }
    if (e.index >= sparse_.size()) sparse_.resize(e.index + 1, kAbsent);
    sparse_[e.index] = static_cast<std::uint32_t>(dense_.size());
    dense_.push_back(std::move(value));
    entities_.push_back(e);
    return dense_.back();
  }

  T* get(Entity e) { return contains(e) ? &dense_[sparse_[e.index]] : nullptr; }
  const T* get(Entity e) const { return contains(e) ? &dense_[sparse_[e.index]] : nullptr; }

  void remove(Entity e) override {
    if (!contains(e)) return;
    const std::uint32_t at = sparse_[e.index];
    const std::uint32_t last = static_cast<std::uint32_t>(dense_.size() - 1);
    if (at != last) {
      dense_[at] = std::move(dense_[last]);
      entities_[at] = entities_[last];
      sparse_[entities_[at].index] = at;
    }
    dense_.pop_back();
    entities_.pop_back();
    sparse_[e.index] = kAbsent;
  }

  void clear() override {
    dense_.clear();
    entities_.clear();
    sparse_.clear();
  }

  // Dense access for data-parallel loops: index i belongs to entities()[i].
  std::vector<T>& components() { return dense_; }
  const std::vector<T>& components() const { return dense_; }

  void serialize(BinaryWriter& out) const override {
    out.pod<std::uint64_t>(dense_.size());
    for (std::size_t i = 0; i < dense_.size(); ++i) {
      out.pod(entities_[i].index);
      out.pod(entities_[i].generation);
      FieldWriter w{out};
      const_cast<T&>(dense_[i]).visitFields(w);  // visitFields is read-only for FieldWriter
    }
  }

  void deserialize(BinaryReader& in, std::size_t slotCount) override {
    clear();
    const auto n = in.pod<std::uint64_t>();
    if (n > slotCount) in.fail("pool '" + name_ + "' holds more components than there are entities");
    for (std::uint64_t i = 0; i < n; ++i) {
      Entity e;
      e.index = in.pod<std::uint32_t>();
      e.generation = in.pod<std::uint32_t>();
      if (e.index >= slotCount) in.fail("pool '" + name_ + "' names entity #" + std::to_string(e.index) + " beyond the entity table");
      T value{};
      FieldReader r{in};
      value.visitFields(r);
      if constexpr (HasAfterLoad<T>::value) value.afterLoad();
      add(e, std::move(value));
    }
  }

  std::string fieldLayout() const override {
    T value{};
    FieldLayoutWriter w;
    value.visitFields(w);
    return w.layout;
  }

  std::optional<ComponentViolation> firstViolation(double maxAbs) const override {
    for (std::size_t i = 0; i < dense_.size(); ++i) {
      FieldSanityChecker c{maxAbs, std::nullopt};
      const_cast<T&>(dense_[i]).visitFields(c);
      if (c.found) return ComponentViolation{entities_[i], name_, *c.found};
    }
    return std::nullopt;
  }

 private:
  std::string name_;
  std::vector<T> dense_;
  std::vector<Entity> entities_;
  std::vector<std::uint32_t> sparse_;
};

}  // namespace monolith
