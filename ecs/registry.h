#pragma once
// Component and system types by stable name. Built-in types register at start-up through
// explicit calls (registerBuiltins), plugins through their entry point; nothing registers
// through static initialisers.
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "ecs/config.h"
#include "ecs/system.h"
#include "ecs/world.h"

namespace monolith {

template <int d>
struct ComponentType {
  std::string name;
  std::string summary;
  // Reads the entity's config of this component (the object under the component's key) and
  // adds the component. Null for internal components that scenes cannot name.
  std::function<void(World<d>&, Entity, const Config&)> parse;
  // Creates an empty pool of the right type (needed to restore a checkpoint).
  std::function<void(World<d>&)> ensurePool;
  std::string origin;  // "built-in" or the plugin's path
};

template <int d>
struct SystemType {
  std::string name;
  std::string summary;
  // One type may yield several instances (a force evaluated at both Newmark time levels).
  std::function<std::vector<std::unique_ptr<System<d>>>()> create;
  std::string origin;
};

class Registry {
 public:
  template <int d>
  void addComponent(ComponentType<d> type);
  template <int d>
  void addSystem(SystemType<d> type);

  template <int d>
  const std::vector<ComponentType<d>>& components() const;
  template <int d>
  const std::vector<SystemType<d>>& systems() const;
  template <int d>
  const ComponentType<d>* findComponent(const std::string& name) const;

  // Origin recorded for everything registered until the next call.
  void setOrigin(std::string origin) { origin_ = std::move(origin); }

  // Instances of every registered system type, in registration order.
  template <int d>
  std::vector<std::unique_ptr<System<d>>> instantiateSystems() const;

  // Convenience for component types T with T::kName.
  template <int d, class T>
  void addComponentOf(std::string summary, std::function<void(World<d>&, Entity, const Config&)> parse) {
    addComponent<d>(ComponentType<d>{T::kName, std::move(summary), std::move(parse),
                                     [](World<d>& w) { w.template ensurePool<T>(); }, ""});
  }

 private:
  std::vector<ComponentType<2>> components2_;
  std::vector<ComponentType<3>> components3_;
  std::vector<SystemType<2>> systems2_;
  std::vector<SystemType<3>> systems3_;
  std::string origin_ = "built-in";
};

// The built-in component and system types (components/, systems/).
void registerBuiltins(Registry& registry);

}  // namespace monolith
