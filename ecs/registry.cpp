#include "ecs/registry.h"

#include <stdexcept>

namespace monolith {

namespace {
template <class List, class Item>
void addUnique(List& list, Item item, const std::string& kind) {
  for (const auto& existing : list)
    if (existing.name == item.name)
      throw std::invalid_argument(kind + " type '" + item.name + "' is registered twice (by " + existing.origin +
                                  " and by " + item.origin + ")");
  list.push_back(std::move(item));
}
}  // namespace

template <>
void Registry::addComponent<2>(ComponentType<2> t) {
  t.origin = origin_;
  addUnique(components2_, std::move(t), "component");
}
template <>
void Registry::addComponent<3>(ComponentType<3> t) {
  t.origin = origin_;
  addUnique(components3_, std::move(t), "component");
}
template <>
void Registry::addSystem<2>(SystemType<2> t) {
  t.origin = origin_;
  addUnique(systems2_, std::move(t), "system");
}
template <>
void Registry::addSystem<3>(SystemType<3> t) {
  t.origin = origin_;
  addUnique(systems3_, std::move(t), "system");
}
template <>
const std::vector<ComponentType<2>>& Registry::components<2>() const { return components2_; }
template <>
const std::vector<ComponentType<3>>& Registry::components<3>() const { return components3_; }
template <>
const std::vector<SystemType<2>>& Registry::systems<2>() const { return systems2_; }
template <>
const std::vector<SystemType<3>>& Registry::systems<3>() const { return systems3_; }

template <int d>
const ComponentType<d>* Registry::findComponent(const std::string& name) const {
  for (const auto& c : components<d>())
    if (c.name == name) return &c;
  return nullptr;
}
template const ComponentType<2>* Registry::findComponent<2>(const std::string&) const;
template const ComponentType<3>* Registry::findComponent<3>(const std::string&) const;

template <int d>
std::vector<std::unique_ptr<System<d>>> Registry::instantiateSystems() const {
  std::vector<std::unique_ptr<System<d>>> all;
  for (const auto& type : systems<d>())
    for (auto& s : type.create()) all.push_back(std::move(s));
  return all;
}
template std::vector<std::unique_ptr<System<2>>> Registry::instantiateSystems<2>() const;
template std::vector<std::unique_ptr<System<3>>> Registry::instantiateSystems<3>() const;

}  // namespace monolith
