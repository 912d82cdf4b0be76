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

// How rigid orientations are advanced in Step IV (Sec. 4.4.1, App. A, Sec. 2.2).
struct RigidRotationSettings {
  int order = 2;           // 1: exp(dt w*) [169]; 2: Sec. 4.4.1; 3: App. A
  bool energyFix = true;   // kinetic-energy orientation fix, Sec. 2.2.2-2.2.4
};

// How the fluid step of Ch. 5 is taken (scene "solvers": {"fluid": {...}}).
struct FluidSolverSettings {
  enum class Advection { SemiLagrangian, MacCormack, Eno3, Weno5, None };  // None: unsteady Stokes flow (Sec. 5.7)
  enum class Projection { Coupled, Chorin };            // (5.31) vs pressure/viscosity splitting
  enum class Preconditioner { None, Jacobi, IC0, MIC0, Multigrid };
  Advection advection = Advection::SemiLagrangian;
  Projection projection = Projection::Coupled;
  Preconditioner preconditioner = Preconditioner::Multigrid;  // flat iteration counts (benchmarks)
  // The coupled solve's preconditioner around the Poisson one: false (scene
  // "coupled_preconditioner": "block_diagonal"): the Poisson preconditioner and a Jacobi viscous
  // block (notes 4.4); true ("cut_corrected", default): the same plus an exact solve on the band
  // of unknowns around cut faces (solvers/fluid/coupled_preconditioner.h). Identical without cut faces.
  bool coupledCutCorrection = true;
  double tolerance = 1e-8;   // relative residual of the Krylov solve
  int maxIterations = 5000;
  // Where the viscous operator puts an obstacle's no-slip wall (scene "obstacle_wall"):
  //  * Face ("face", default): at the obstacle face's centre, the thesis's first-order treatment
  //    (Sec. 5.4.1, 5.7), up to a cell inside the body;
  //  * Surface ("surface"): at the body's true surface, found along each pair's direction;
  //  * CellBoundary ("cell_boundary", staircase only): at the boundary of the solid cells, half a
  //    cell from the first fluid face, where a finite-volume code on the same staircase puts it.
  // The last two store wall distances (docs/architecture.md, measured in docs/benchmarks.md).
  enum class ObstacleWall { Face, Surface, CellBoundary };
  ObstacleWall obstacleWall = ObstacleWall::Face;
  bool obstacleWallDistances() const { return obstacleWall != ObstacleWall::Face; }
  // Where the advection's samples see that wall: false ("advection_wall": "face", default): behind
  // the first fluid faces they read the obstacle faces' own velocity or, inside the body, extend
  // the fluid's (velocity_sampling.h rules 3-4, the thesis's clipping of Sec. 5.2); true
  // ("surface", needs obstacle wall distances): ghost values continue the velocity linearly through
  // the wall at the distance the viscous operator uses (solvers/advection/wall_ghosts.h).
  bool advectionWallAtSurface = false;
  // How obstacles meet the pressure: false (scene "obstacle_cells": "staircase", default): cells
  // with the centre inside are solid, their faces carry the body's velocity (Sec. 5.4.1); true
  // ("cut"): faces cut by the body keep their open part as fluid (solvers::cutFaces).
  bool cutCells = false;
};

// Collisions, contact and interpenetration resolution (scene "solvers": {"contact": {...}}).
// The defaults are the thesis code's schedule (notes 1.4, 1.6, 1.7). `"schedule": "short"`
// (useShortSchedule, docs/rigid_contact.md) is one contact sweep of one level pass, one
// shock-propagation pass, exact manifold solves, contact that lets a gap close in the step and
// the step energy clamp: 12-15x cheaper per awake step, not the default because 2-D random
// drops still sink deeper than 5 % for a step on it (2 of 838; docs/rigid_contact.md).
struct ContactSettings {
  int collisionIterations = 5;       // Gauss-Seidel sweeps over the pairs (Step II)
  int collisionPairIterations = 20;  // impulses per pair per sweep
  int contactIterations = 10;        // outer contact sweeps (Step III), epsilon-scaled
  int contactLevelIterations = 2;    // per level and sweep
  int contactPairIterations = 10;    // Gauss-Seidel sweeps of one pair's manifold solve (measured)
  bool shockPropagation = true;      // GBF 2003 shock propagation after contact
  int shockLevelIterations = 2;      // the thesis code's
  int shockPairIterations = 40;      // measured: a 2-D pyramid's joint solves need them (docs/benchmarks.md)
  // Manifold and joint solves end with an exact active-set step once it applies
  // (solvers/contact/manifold_polish.h; not in the thesis, whose sweeps stop at their count).
  // Off by default: at the thesis's schedule it costs 3-30 % more than it saves on three of five
  // scenes; on the short schedule it makes the step 3x faster and leaves a standing pyramid
  // exactly at rest.
  bool exactManifoldFinish = false;
  bool pushOut = true;               // interpenetration resolution, Sec. 4.6.1 / App. B
  int pushOutLevelIterations = 6;    // thesis code: 2; measured on piles (the git history of docs/benchmarks.md ("Six push-out passes"))
  int pushOutBodyIterations = 5;
  // Push-out also separates pairs that Steps II-III never saw interpenetrating (not "processed")
  // but that overlap after Step IV's positions: a body moved by contact or by another push-out
  // into a neighbour (not in the thesis, whose push-out keeps to the saved pairs; Sec. 4.6.1).
  bool pushOutNewOverlaps = true;
  // With pushOutNewOverlaps: rounds of push-out while a push carries a body into one it was not
  // paired with (found only by the broad phase grown after the round; not in the thesis).
  int pushOutRounds = 4;
  // ... and while a pair still overlaps by more than this fraction of its smaller body's size.
  double pushOutRoundOverlap = 0.02;
  // ... and then, where the rounds leave a pair overlapping by more than pushOutJointOverlap of
  // its smaller body's size (a jam), the bodies of those pairs and their overlapping dynamic
  // neighbours (two rings) pushed apart all at once (solvers/contact/joint_push_out.h; not in the
  // thesis), pass by pass while each leaves them shallower.
  bool pushOutJoint = true;
  double pushOutJointOverlap = 0.05;
  bool velocityContact = true;       // second contact step in Step V (Sec. 2.3.2 "Contact Clamping")
  bool energyClamp = true;           // Sec. 2.3.2 for collisions and the second contact step
  // After Step V, an island of bodies moved only by gravity and contact whose energy (kinetic +
  // gravity's potential) rose in the step has its velocities scaled down to take the rise back
  // (not in the thesis, which leaves the first contact step unclamped, Sec. 2.3.2; systems/
  // step_energy_clamp.cpp). The short schedule needs it: its one inelastic contact pass can lift
  // a spinning body for the position update without paying for the rise.
  bool stepEnergyClamp = false;
  // Contact (Steps III and V) lets each point close the gap its bodies have at the base poses
  // within the step: v_n >= -gap/dt instead of v_n >= 0 (not in the thesis, whose ramped sweeps
  // close such gaps approximately). Without it one fully inelastic pass stops a body falling
  // onto a support closer than its step's fall in the air above it.
  bool closeGaps = false;
  // Step II: a pair moving more than half its thinner body's size in the step is tested at its
  // first contact along the motion instead of at the candidate poses (not in the thesis;
  // solvers/collision/swept_contact.h).
  bool sweptCollisions = true;
  double thickness = 1e-4;           // contact is processed within this separation (m)
  double pushOutTolerance = 1e-5;    // penetration left alone by push-out (m)
  double approachTolerance = 1e-9;   // |v_rel.n| below this is "not approaching" (m/s)
  // Sleeping (not in the thesis; systems/sleep.h): an island of dynamic bodies whose every point
  // has moved slower than sleepSpeed for sleepTime is held still until an awake or moving body
  // touches it. Off by default: it stops bodies the thesis's scheme would still move by up to
  // sleepSpeed. Box2D's defaults are 0.01 m/s (and 2 degrees/s) for 0.5 s.
  bool sleep = false;
  double sleepSpeed = 0.01;          // m/s, at the body's farthest point from its centre of mass
  double sleepTime = 0.5;            // s

  // The short schedule: one contact sweep of one level pass, one shock-propagation pass, manifold
  // solves finished exactly, gaps closed, and the step energy clamp.
  void useShortSchedule() {
    contactIterations = 1;
    contactLevelIterations = 1;
    shockLevelIterations = 1;
    exactManifoldFinish = true;
    stepEnergyClamp = true;
    closeGaps = true;
    pushOutJointOverlap = 0.02;
  }
  // The thesis code's schedule (the defaults above): ten epsilon-ramped contact sweeps of two
  // level passes, two shock-propagation passes, manifold solves by sweeps alone, no gap closing,
  // no step clamp.
  void useThesisSchedule() {
    contactIterations = 10;
    contactLevelIterations = 2;
    shockLevelIterations = 2;
    exactManifoldFinish = false;
    stepEnergyClamp = false;
    closeGaps = false;
    pushOutJointOverlap = 0.05;
  }
};

// Scene-wide physical settings shared by systems (read-only during a step).
template <int d>
struct WorldSettings {
  Vec<d> gravity = Vec<d>::Zero();
  RigidRotationSettings rigidRotation;
  ContactSettings contact;
  FluidSolverSettings fluid;
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
};

}  // namespace monolith
