#pragma once
// The rigid collision and contact stages of the Newmark step (thesis Sec. 4.2), one
// system per stage, sharing one ContactWorkspace per step:
//   collisions               Step II  (Sec. 4.4): v^n -> \hat v^n, pairwise Gauss-Seidel, restitution
//                                     and friction, energy clamp against (x^n, v^n); then
//                                     \hat v^{n+1/2} = \hat v^n + (\tilde v^{n+1/2} - v^n)
//   contact                  Step III (Sec. 4.5): contact graph, epsilon-scaled inelastic contact on
//                                     the pairs collisions processed, level by level; no clamp
//   shock_propagation        Step III (GBF 2003 [64]): bottom-up, each level frozen after it is done
//   resolve_interpenetration Step IV  (Sec. 4.6.1, App. B): central-body push-out, then the
//                                     velocity is reset to \hat v^n (+ the Step I kick)
//   velocity_contact         Step V   (Sec. 2.3.2 "Contact Clamping"): contact again on the pairs
//                                     contact touched, clamped against (x^{n+1}, v^{n+1})
//   fall_asleep              after Step V, with sleeping on (not in the thesis; systems/sleep.h):
//                                     islands that have been still long enough are held still
#include <memory>
#include <utility>
#include <vector>

#include "ecs/system.h"
#include "solvers/contact/joint_push_out.h"
#include "systems/contact_workspace.h"

namespace monolith {

template <int d>
class RigidContactSystem : public System<d> {
 public:
  explicit RigidContactSystem(std::shared_ptr<ContactWorkspace<d>> ws) : ws_(std::move(ws)) {}
  std::vector<std::string> reads() const override {
    return {Collider<d>::kName, Shape<d>::kName, RigidForces<d>::kName, KinematicMotion<d>::kName};
  }
  // Sleep: Step II wakes bodies (wakeTouchedSleepers), fall_asleep puts them to sleep.
  std::vector<std::string> writes() const override {
    return {RigidBody<d>::kName, "contact_workspace", Sleep<d>::kName};
  }
  bool needed(const World<d>& w) const override { return w.template count<Collider<d>>() > 0; }

 protected:
  std::shared_ptr<ContactWorkspace<d>> ws_;
};

template <int d>
class Collisions final : public RigidContactSystem<d> {
 public:
  using RigidContactSystem<d>::RigidContactSystem;
  std::string name() const override { return "collisions"; }
  Stage stage() const override { return Stage::Collisions; }
  void run(World<d>& world, StepContext& ctx) override;
};

template <int d>
class Contact final : public RigidContactSystem<d> {
 public:
  using RigidContactSystem<d>::RigidContactSystem;
  std::string name() const override { return "contact"; }
  Stage stage() const override { return Stage::Contact; }
  void run(World<d>& world, StepContext& ctx) override;
};

template <int d>
class ShockPropagation final : public RigidContactSystem<d> {
 public:
  using RigidContactSystem<d>::RigidContactSystem;
  std::string name() const override { return "shock_propagation"; }
  Stage stage() const override { return Stage::Contact; }
  bool needed(const World<d>& w) const override {
    return RigidContactSystem<d>::needed(w) && w.settings().contact.shockPropagation;
  }
  void run(World<d>& world, StepContext& ctx) override;
};

template <int d>
class ResolveInterpenetration final : public RigidContactSystem<d> {
 public:
  using RigidContactSystem<d>::RigidContactSystem;
  std::string name() const override { return "resolve_interpenetration"; }
  Stage stage() const override { return Stage::AdvancePositions; }
  void run(World<d>& world, StepContext& ctx) override;

  // One island's push-out plan: its tasks (one per central body and level iteration, then the
  // level's freezes) and the buffers that build them. Kept per island slot across steps, so a
  // pile of thousands of small islands does not allocate them anew every step.
  struct PushTask {
    int central = -1;  // -1: freeze `frozenBody`
    int frozenBody = -1;
    int begin = 0, end = 0;  // the central body's pairs on its level, in `centralPairs`
    double fraction = 0;
  };
  struct IslandPlan {
    std::vector<PushTask> tasks;
    std::vector<int> centralPairs;  // per central body and level: its pairs there, in level order
    std::vector<char> frozen;
    std::vector<int> touched, levelMembers, solves;
    std::vector<std::pair<int, int>> bodyPair;  // (level member, pair), grouped by member
    std::vector<std::pair<int, int>> range;     // per level member: its pairs in centralPairs
    std::vector<int> pairsByLevel;  // the island's pairs to push apart, ascending level
    std::vector<std::pair<int, int>> focusByLevel;  // a focused round's bodies: (level, body)
    solvers::parallel::OrderedTasks order;
  };

 private:
  // The rotational-energy clamp on the momentum Step V starts from (3-D;
  // systems/rotational_energy_clamp.cpp): what
  // it needs from before push-out, then the clamp (returns the bodies it scaled).
  void rememberRotationalEnergy(const ContactWorkspace<d>& ws);
  int clampEnergyOfRestoredMomentum(ContactWorkspace<d>& ws);
  struct AdvancedState {
    solvers::contact::AngVec<d> L;
    Orientation<d> q;
  };
  std::vector<double> energyAtTimeN_;     // per body: the restored momentum's energy at time n
  std::vector<AdvancedState> advanced_;   // per body: Step IV's momentum and orientation
  std::vector<IslandPlan> plans_;
  // Per pair: its deepest overlap (m) and that over the smaller body's size, as last measured.
  // `which(k)` picks the pairs measured again; the others keep their values.
  template <typename Which>
  void measurePairs(const ContactWorkspace<d>& ws, Which&& which);
  std::vector<double> depth_, ratio_;
  // Per pair: whether it overlaps though Step II did not process it (newOverlap_); returns how
  // many do.
  int markNewOverlaps(const ContactWorkspace<d>& ws);
  // The levels push-out runs by (pairLevel_ per pair): the contact graph's, or with new overlaps
  // those of its copy with an edge both ways per new overlap (newOverlap_, which a later round
  // also sets for the pairs it ties, tie_).
  const solvers::contact::ContactLevels& pushLevels(const ContactWorkspace<d>& ws, int newOverlaps);
  // One round of push-out over the islands marked in active_; returns the central-body solves.
  // focused: only the pairs with a body in focus_ (the rounds after the first).
  int pushApart(ContactWorkspace<d>& ws, const solvers::contact::ContactLevels& levels, bool focused);
  struct SavedPose {
    int body;
    Eigen::Matrix<double, d, 1> x;
    Orientation<d> q;
  };
  std::vector<SavedPose> savedPoses_;  // a later round's bodies before it, to undo it
  std::vector<char> active_;      // per island: pushed apart in this round
  std::vector<char> focus_;       // per body: worked on in the next round
  std::vector<char> partner_;     // per body: a dynamic neighbour of a focus body
  std::vector<char> tie_;         // per pair of two dynamic bodies: one level in the next round
  std::vector<std::pair<int, int>> knownPairs_;  // the pairs before a round's growth
  std::vector<double> knownDepth_, knownRatio_;  // and their measurements
  std::vector<int> knownIndex_;                  // per pair after the growth: its index before, or -1
  std::vector<char> moved_;       // per body: in an island push-out worked on
  // The pairs whose depths growAndMeasure measured again: a body in moved_, or new.
  bool movedOrNew(const ContactWorkspace<d>& ws, std::size_t k) const;
  // After bodies in moved_ moved: the broad phase grown where they are, the depths carried over
  // and measured again (movedOrNew); returns the pairs added.
  int growAndMeasure(ContactWorkspace<d>& ws);
  // The jam left after the rounds pushed apart at once (solvers/contact/joint_push_out.h), pass
  // by pass while each leaves its pairs shallower. Returns the passes kept; adds to newPairs.
  // The jam is the deep pairs' bodies and `rings` rings of their dynamic neighbours.
  int pushJamsApart(ContactWorkspace<d>& ws, int rings, int& newPairs);
  static constexpr int kJointPasses = 16;  // linearisations, at most
  static constexpr int kJointHalvings = 3;  // of a pass's step that leaves the jam no shallower
  static constexpr int kJointRings = 2;    // neighbours of neighbours of the deep pairs' bodies
  static constexpr int kJointRegrowths = 3;  // solves again with 4, 8, 16 rings, at most
  std::vector<char> jamRing_, jamNext_;    // the bodies a ring grows from, and those it adds
  static constexpr int kJointSweeps = 2000;  // Gauss-Seidel sweeps per linearisation, at most
  std::vector<int> jamIndex_;  // per body: its index in the joint solve, or -1 (a fixed partner)
  std::vector<solvers::contact::JointBody<d>> jamBodies_;
  std::vector<solvers::contact::JointPoint<d>> jamPoints_;
  std::vector<solvers::contact::JointMove<d>> jamMoves_;
  std::vector<solvers::collision::ContactPoint<d>> jamContacts_;  // one pair's narrow phase, kept
  std::vector<SavedPose> passStart_;  // the jam's bodies and their poses before a pass, to undo it
  std::vector<char> newOverlap_;  // per pair: not processed in Step II, yet overlapping now (or tied)
  std::vector<int> pairLevel_;    // per pair: its level in push-out
  std::vector<std::pair<int, int>> edges_;
  solvers::contact::ContactLevels pushLevels_;
};

template <int d>
class VelocityContact final : public RigidContactSystem<d> {
 public:
  using RigidContactSystem<d>::RigidContactSystem;
  std::string name() const override { return "velocity_contact"; }
  Stage stage() const override { return Stage::AdvanceVelocity; }
  bool needed(const World<d>& w) const override {
    return RigidContactSystem<d>::needed(w) && w.settings().contact.velocityContact;
  }
  void run(World<d>& world, StepContext& ctx) override;
};

// Sleeping (not in the thesis; systems/sleep.h): after Step V, every dynamic body of an island
// (the bodies the step's pairs join) that has moved slower than sleep_speed for sleep_time is
// put to sleep with the others of its island, at rest.
template <int d>
class FallAsleep final : public RigidContactSystem<d> {
 public:
  using RigidContactSystem<d>::RigidContactSystem;
  std::string name() const override { return "fall_asleep"; }
  Stage stage() const override { return Stage::AdvanceVelocity; }
  bool needed(const World<d>& w) const override {
    return RigidContactSystem<d>::needed(w) && w.template count<Sleep<d>>() > 0;
  }
  void run(World<d>& world, StepContext& ctx) override;

 private:
  std::vector<double> reach_;  // per body: its farthest point's distance from its centre of mass
  std::vector<const solvers::collision::PreparedGeometry<d>*> reachOf_;  // the geometry reach_ is of
  std::vector<int> parent_;    // union-find over the step's pairs
  std::vector<char> blocked_;  // per island root: a member that may not sleep yet
  std::vector<char> held_;     // per body, then per island root: at rest without being pushed
};

// The systems above sharing one workspace, in pipeline order.
template <int d>
std::vector<std::unique_ptr<System<d>>> makeRigidContactSystems();

}  // namespace monolith
