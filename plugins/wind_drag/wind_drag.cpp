// Example plugin: aerodynamic drag on rigid bodies relative to a uniform wind,
//   F = -k_lin (v - w) - k_quad |v - w| (v - w),
// registered as a component ("wind_drag") and a force system evaluated at both Newmark force
// stages. Built as its own shared object; scenes load it with "plugins": ["path/wind_drag.so"].
#include "components/forces.h"
#include "components/rigid_body.h"
#include "ecs/plugin.h"
#include "systems/rigid_forces.h"

namespace {

using namespace monolith;

template <int d>
struct WindDrag {
  static constexpr const char* kName = "wind_drag";
  double linear = 0;     // k_lin  [N s / m]
  double quadratic = 0;  // k_quad [N s^2 / m^2]
  Eigen::Matrix<double, d, 1> wind = Eigen::Matrix<double, d, 1>::Zero();
  Eigen::Matrix<double, d, 1> startVelocity = Eigen::Matrix<double, d, 1>::Zero();  // v^n of the current step
  template <class V>
  void visitFields(V& visit) {
    visit("linear", linear);
    visit("quadratic", quadratic);
    visit("wind", wind);
    visit("start_velocity", startVelocity);
  }
};

// Explicit in the velocity. At ForcesAtStart it uses v^n (and remembers it); at ForcesAtEnd it
// uses the extrapolated v^{n+1} ~ 2 v^{n+1/2} - v^n (the extrapolation of the thesis' Step V,
// Sec. 4.7). Evaluating it at v^{n+1/2} instead would make the step only first-order accurate
// for a velocity-dependent force: the two half kicks would add dt^2/4 a'a instead of dt^2/2 a'a.
template <int d>
class WindDragForce final : public RigidForceSystem<d> {
 public:
  explicit WindDragForce(Stage s) : RigidForceSystem<d>("wind_drag", s) {}
  std::vector<std::string> reads() const override { return {RigidBody<d>::kName}; }
  std::vector<std::string> writes() const override { return {RigidForces<d>::kName, WindDrag<d>::kName}; }
  bool needed(const World<d>& w) const override { return w.template count<WindDrag<d>>() > 0; }
  void run(World<d>& world, StepContext&) override {
    auto& drags = world.template pool<WindDrag<d>>();
    for (std::size_t i = 0; i < drags.size(); ++i) {
      const Entity e = drags.entities()[i];
      const auto* body = world.template get<RigidBody<d>>(e);
      auto* f = world.template get<RigidForces<d>>(e);
      if (!body || !f) continue;
      WindDrag<d>& c = drags.components()[i];
      Eigen::Matrix<double, d, 1> velocity = body->v;
      if (this->stage() == Stage::ForcesAtStart) c.startVelocity = body->v;
      else velocity = 2 * body->v - c.startVelocity;
      const Eigen::Matrix<double, d, 1> relative = velocity - c.wind;
      f->force -= (c.linear + c.quadratic * relative.norm()) * relative;
    }
  }
};

template <int d>
void parseWindDrag(World<d>& world, Entity e, const Config& c) {
  WindDrag<d> w;
  w.linear = c.number("linear", 0.0, Bound::NonNegative);
  w.quadratic = c.number("quadratic", 0.0, Bound::NonNegative);
  w.wind = c.vector("wind", Eigen::VectorXd::Zero(d));
  if (!world.template has<RigidBody<d>>(e)) c.fail("a wind_drag on an entity with a rigid_body", "no rigid_body");
  world.add(e, w);
}

template <int d>
void registerDimension(Registry& r) {
  r.addComponentOf<d, WindDrag<d>>("drag relative to a uniform wind: linear, quadratic, wind", parseWindDrag<d>);
  r.addSystem<d>({"wind_drag", "F = -(k_lin + k_quad |v-w|)(v-w) on bodies with wind_drag",
                  [] { return atBothForceStages<WindDragForce<d>, d>(); }, ""});
}

}  // namespace

MONOLITH_PLUGIN_ABI()

extern "C" int monolith_plugin_register(monolith::Registry* registry) {
  registerDimension<2>(*registry);
  registerDimension<3>(*registry);
  return 0;
}
