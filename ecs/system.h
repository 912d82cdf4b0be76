#pragma once
// A system changes components. It declares, in one place, its name, its stage, what it reads
// and writes (component names, or resource names such as "contact_graph"), and whether the
// scene needs it at all. The scheduler derives the task graph from these declarations only.
#include <limits>
#include <string>
#include <vector>

#include "ecs/stage.h"
#include "ecs/step_context.h"
#include "ecs/world.h"

namespace monolith {

template <int d>
class System {
 public:
  static constexpr int dimension = d;
  virtual ~System() = default;
  virtual std::string name() const = 0;
  virtual Stage stage() const = 0;
  virtual std::vector<std::string> reads() const = 0;
  virtual std::vector<std::string> writes() const = 0;
  // False: the scene lacks what this system acts on, and it is not scheduled at all.
  virtual bool needed(const World<d>& world) const = 0;
  virtual void run(World<d>& world, StepContext& ctx) = 0;
  // The largest stable step at CFL number 1 (e.g. dx / max|u| for a fluid); scenes with
  // "time": {"cfl": c} step by c times the smallest of these. Infinite: no limit.
  virtual double unitCflDt(const World<d>&) const { return std::numeric_limits<double>::infinity(); }
};

}  // namespace monolith
