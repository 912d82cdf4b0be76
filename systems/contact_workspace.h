#pragma once
// The state the rigid collision/contact systems share within one time step: the
// colliding bodies packed in pool order, the candidate poses the pair tests use, the pairs found
// by the broad phase, which of them collisions processed (Step II) and contact touched
// (Step III), the contact-graph levels and the islands. Nothing in it survives a step except
// caches (prepared geometry, broad-phase storage), so checkpoints need nothing from here.
//
// Conventions (notes 7.2): in a pair (a, b) the normal points out of b towards a, a receives
// +j and b receives -j, the relative velocity is v_a - v_b at the point.
#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "components/collider.h"
#include "components/forces.h"
#include "components/kinematic.h"
#include "components/rigid_body.h"
#include "components/shape.h"
#include "components/sleep.h"
#include "ecs/step_context.h"
#include "ecs/world.h"
#include "solvers/collision/broad_phase.h"
#include "solvers/collision/narrow_phase.h"
#include "solvers/collision/swept_contact.h"
#include "solvers/contact/contact_graph.h"
#include "solvers/contact/contact_settings.h"
#include "solvers/contact/manifold_solve_end.h"
#include "solvers/contact/rigid_math.h"
#include "solvers/parallel/ordered_tasks.h"
#include "systems/island_tasks.h"

namespace monolith {

// Shape component -> entity-free collision geometry (throws std::invalid_argument if degenerate).
template <int d>
solvers::collision::Geometry<d> collisionGeometryOf(const Shape<d>& shape);

// exp(theta*) q: an orientation turned by the world rotation vector theta (2-D: an angle).
template <int d>
Orientation<d> rotatedBy(const Orientation<d>& q, const solvers::contact::AngVec<d>& theta) {
  if constexpr (d == 3) {
    const double angle = theta.norm();
    if (angle == 0) return q;
    return (Eigen::Quaterniond(Eigen::AngleAxisd(angle, theta / angle)) * q).normalized();
  } else {
    return q + theta(0);
  }
}

template <int d>
struct ContactBody {
  using VecD = Eigen::Matrix<double, d, 1>;
  using AngV = solvers::contact::AngVec<d>;
  using AngM = solvers::contact::AngMat<d>;

  RigidBody<d>* body = nullptr;
  const solvers::collision::PreparedGeometry<d>* geometry = nullptr;
  bool isStatic = false, kinematic = false;
  bool frozen = false;  // shock propagation / push-out: treated as infinitely massive for now
  // Asleep (components/sleep.h): held still for the whole step, infinitely massive like a static
  // body, but with its own collision geometry (a static box's may reach into the ground).
  bool asleep = false;
  // A sphere with isotropic inertia (3-D): its orientation changes neither its shape in the
  // world nor its world inertia, so candidate poses skip turning it (a sphere pour spent about
  // 15 % of its time there).
  bool turnFree = false;
  double mass = 1, restitution = 0, friction = 0;
  // The base configuration (time n in Steps II-IV, time n+1 in Step V).
  VecD x0 = VecD::Zero();
  Orientation<d> q0 = RigidBody<d>::identityOrientation();
  Eigen::Matrix<double, d, d> R0 = Eigen::Matrix<double, d, d>::Identity();
  AngM inverseInertia0 = AngM::Zero(), inertia0 = AngM::Zero();  // world, at q0
  // Working velocity (what impulses change) and the Step I increment added for candidates.
  VecD v = VecD::Zero();
  AngV L = AngV::Zero();
  VecD dv = VecD::Zero();
  AngV dL = AngV::Zero();
  VecD vCollided = VecD::Zero();  // \hat v^n after Step II, restored after Step IV
  AngV LCollided = AngV::Zero();
  solvers::collision::Pose<d> candidate;
  // World inverse inertia at the candidate orientation: impulses are computed in the split
  // state (GBF 2003; Sec. 2.3.2), the energy clamp measures with the base state's inertia.
  AngM inverseInertiaCandidate = AngM::Zero();
  long movedStamp = 0;

  // Never moved by an impulse in this step, whatever the stage: static, scripted or asleep.
  bool immovable() const { return isStatic || kinematic || asleep; }
  bool infinite() const { return immovable() || frozen; }
  // Held where it is for the whole step (the pose updates skip it).
  bool still() const { return isStatic || asleep; }
  double inverseMass() const { return infinite() ? 0.0 : 1.0 / mass; }
  AngM inverseInertia() const { return infinite() ? AngM::Zero() : inverseInertia0; }
  AngV omega() const { return inverseInertia0 * L; }
  AngM splitInverseInertia() const { return infinite() ? AngM::Zero() : inverseInertiaCandidate; }
  // Velocity at a point with lever arm r (from the centre of mass).
  VecD pointVelocity(const VecD& r) const { return v + solvers::contact::angularCross<d>(omega(), r); }
  double kineticEnergy() const { return infinite() ? 0.0 : 0.5 * mass * v.squaredNorm() + 0.5 * L.dot(omega()); }
};

struct ContactPairState {
  int a = 0, b = 0;
  bool processed = false;  // interpenetrated at candidate positions during Step II
  bool contacted = false;  // received a contact impulse in Step III (used by Step V)
  bool swept = false;      // a collision update found it touching along the step's motion (swept_contact.h)
  long checkedStamp = -1;
  int level = 0;
  // The normal impulse and the net friction impulse (world frame, on a; 2-D uses two entries)
  // the pair's contact updates applied so far in this stage (Step III's contact and shock
  // propagation, or Step V's): Coulomb's law over the stage, which shock propagation's friction
  // may lean on (ContactWorkspace::findPairImpulse, "shockFriction").
  double stageNormal = 0;
  std::array<double, 3> stageFriction = {0, 0, 0};
  // How the pair's last manifold solve ended: the exact finish starts the next solve of the
  // pair from it. Within the step only (findPairs starts it empty).
  solvers::contact::ManifoldSolveEnd end;
  // The pair's slot in the workspace's manifold store (ContactWorkspace::pairContacts); -1: none.
  int manifold = -1;
};

// How a stage moves a body to its candidate pose (GBF 2003): x^0 + dt (v + dv), turned by
// dt I^{-1}(L + dL), with the Step I increment (dv, dL) while the working velocity is v^n (Step
// II's collision sweeps: `kick`), without it once the working velocity is v^{n+1/2} (every later
// stage). Each stage passes its own (its step size is the step context's).
struct CandidateStep {
  double dt = 0;
  bool kick = false;
};

// How one pair update treats the impulse (notes 1.4-1.6, Sec. 2.3.2).
enum class ImpulseMode {
  Collision,        // restitution e, friction clamp, energy clamp against the base state, split lever arms
  Contact,          // restitution -1 + eps, no energy clamp (first contact step)
  ClampedContact,   // restitution -1 + eps, energy clamp against the base state (second contact step)
};

template <int d>
class ContactWorkspace {
 public:
  using VecD = Eigen::Matrix<double, d, 1>;

  // Packs the colliding bodies. `subtractKick`: the bodies carry v^{n+1/2} and the Step I
  // increment dt/2 F/m is taken off to recover v^n (Step II). Their candidate poses are those of
  // CandidateStep{dt, subtractKick}. Returns false if nothing collides.
  bool pack(World<d>& world, double dt, bool subtractKick);
  // Writes the working velocities (and positions, if `positions`) back to the components.
  void unpack(bool positions);
  // The working velocities taken again from the bodies: systems between Step II and Step III
  // (joint post-stabilization and PD, systems/articulation.h) change the bodies' velocities
  // after collisions unpacked them.
  void reloadVelocities();

  // Kinetic energy of the bodies of finite mass (the reference state of the energy clamp,
  // Sec. 2.3.2), in the world frame and, when the scene has exactly one kinematic body and it
  // does not spin (the elevator), in that body's moving frame: the frame in which the clamp
  // bounds impulses against it, and so the one in which a whole stage's change can be checked.
  struct EnergyReading {
    double world = 0, kinematicFrame = 0;
    bool hasKinematicFrame = false;
  };
  EnergyReading readEnergy() const;
  // Sets `<name>` (relative change), `<name>_absolute` and, with a kinematic frame,
  // `<name>_kinematic_frame` (relative change in that frame).
  static void reportEnergyChange(DiagnosticsSink& out, const std::string& name, const EnergyReading& before,
                                 const EnergyReading& after);

  // Candidate pose x0 + dt (v + kick*dv), rotated by dt * I^{-1}(L + kick*dL) (first order:
  // candidates only decide which pairs touch).
  static void updateCandidate(ContactBody<d>& b, const CandidateStep& step);
  // The velocity of the frame in which an impulse against `partner`, a body of infinite mass,
  // is energy-clamped (r: the contact point from the partner's centre).
  VecD clampFrameVelocity(const ContactBody<d>& partner, const VecD& r) const;
  // The motion from the base pose to the candidate pose (swept collisions).
  static solvers::collision::StepMotion<d> stepMotion(const ContactBody<d>& b, const CandidateStep& step);
  void updateAllCandidates(const CandidateStep& step);

  // Broad phase at the candidate poses, then islands; resets pair flags.
  void findPairs();
  // Step II's start with sleeping on (systems/sleep.cpp): wakes the sleeping bodies a pair of
  // findPairs joins to an awake dynamic body, and those whose box a moving kinematic body's
  // reaches, each with the bodies it fell asleep with; gives them the Step I kick they missed,
  // packs again and finds the pairs again, until nothing more wakes. Returns the bodies woken.
  int wakeTouchedSleepers(World<d>& world, double dt);
  // The entity of bodies[i].
  Entity entityOf(std::size_t i) const { return entities_[i]; }
  // Contact-graph levels from the processed pairs (Step III item 1, notes 1.6). First grows the
  // pair list to where the collision impulses sent the bodies (growPairs); returns the pairs
  // that added. `dt`: the step (the bodies re-advanced over it).
  int computeLevels(double dt);
  // Grows each body's broad-phase box to cover `poses(body)` too (a list of poses). If any box
  // grew, the broad phase runs again: its pairs are a superset of the known ones, which keep
  // their state; new ones start unprocessed. Islands and the per-island level lists follow.
  // Returns the number of new pairs. Not in the thesis: the boxes of findPairs cover the motion
  // with the velocities before Step II, and a body an impulse sends elsewhere (a bounce) could
  // otherwise meet a body it was never paired with, unseen by every later stage
  // (docs/architecture.md, "Pairs found again after the impulses").
  template <typename PosesOf>
  int growPairs(PosesOf&& poses);
  // The pose at x^n + dt (v + k dv): k = 1 re-advances with the Step I kick (notes 1.6).
  static solvers::collision::Pose<d> reAdvanced(const ContactBody<d>& b, double dt, double k);

  // What one pair's manifold solve asks for: the net impulse J on A (-J on B), A's angular
  // impulse tau about its centre, the energy clamp's scale, and how many points carry impulse
  // (0: nothing to apply). fromB = x_a - x_b where the pair was tested.
  struct PairImpulse {
    int active = 0;
    VecD J = VecD::Zero();
    solvers::contact::AngVec<d> tau = solvers::contact::AngVec<d>::Zero();
    double scale = 1;
    VecD fromB = VecD::Zero();
  };
  // One pair update: the pair's manifold at the candidate poses, its impulses solved together
  // (at most `iterations` sweeps) and applied. Returns how many points carry impulse.
  int updatePair(ContactPairState& pair, ImpulseMode mode, const CandidateStep& step, double epsilon, int iterations,
                 double margin, std::vector<solvers::collision::ContactPoint<d>>& scratch, double* clampEnergyChange,
                 int* clampsApplied, bool shockFriction = false) {
    ContactBody<d>& A = bodies[pair.a];
    ContactBody<d>& B = bodies[pair.b];
    const PairImpulse r = findPairImpulse(pair, A, B, mode, step, epsilon, iterations, margin, scratch,
                                          clampEnergyChange, clampsApplied, shockFriction);
    if (r.active > 0) applyPairImpulse(pair, A, B, r, mode, step);
    return r.active;
  }
  // The update's first half: finds the impulse, only reading the bodies (the speculative sweep
  // runs it on many pairs at once). The pair's own state (processed, swept, the solve's end,
  // the stage's impulses) is updated as the update leaves it.
  // shockFriction (shock propagation; not in the thesis): the pair's friction may lean on the
  // normal impulse it carried earlier in the stage, and the pair is solved when it slides even
  // if nothing approaches. The contact sweeps before it remove the approach, so without this
  // shock propagation's updates carry no normal impulse and cannot stop the slip those sweeps
  // leave (an off-centre box on a box walked at millimetres per second).
  PairImpulse findPairImpulse(ContactPairState& pair, const ContactBody<d>& A, const ContactBody<d>& B,
                              ImpulseMode mode, const CandidateStep& step, double epsilon, int iterations,
                              double margin, std::vector<solvers::collision::ContactPoint<d>>& scratch,
                              double* clampEnergyChange, int* clampsApplied, bool shockFriction = false) const;
  // The second half: the impulse on both bodies (those of finite mass), their candidates
  // re-advanced; a contact impulse marks the pair contacted (Step V's list).
  void applyPairImpulse(ContactPairState& pair, ContactBody<d>& A, ContactBody<d>& B, const PairImpulse& r,
                        ImpulseMode mode, const CandidateStep& step) const;

  // One Gauss-Seidel collision sweep (Step II, notes 1.4) over one island's pairs; `sweep` counts
  // from 0. A pair is skipped when it was checked after both its bodies last moved. Returns the
  // number of impulses applied.
  int collisionSweep(int island, int sweep, const CandidateStep& step, double* clampEnergyChange, int* clampsApplied);

  // The epsilon-scaled contact sweeps of notes 1.6 over one island: contact iterations, each
  // level from the bottom, level iterations, eps = (it+1)(li+1)/(iterations*level iterations).
  int contactSweeps(int island, ImpulseMode mode, const CandidateStep& step, bool onlyContacted,
                    double* clampEnergyChange, int* clampsApplied);

  // The contact manifold of a pair for the contact stages (Steps III and V) at the bodies'
  // candidate poses, with `first` (the pair's a, or its b when `firstIsB`) as findContacts's A:
  // appended to `out`, returns the count. The narrow phase runs once per pair and relative pose;
  // while the bodies stay within reach of that pose the points are carried along with them
  // instead (see the definition: which pairs, how far, and what the carried points miss).
  int pairContacts(const ContactPairState& pair, bool firstIsB, const ContactBody<d>& first,
                   const ContactBody<d>& second, const solvers::collision::ContactQuery& query,
                   std::vector<solvers::collision::ContactPoint<d>>& out) const;

  // Joint contact solve of body c against the bodies of infinite mass among `count` pairs.
  int updateBodyAgainstFrozen(int c, const int* pairList, int count, ImpulseMode mode, const CandidateStep& step,
                              double epsilon, int iterations, double margin,
                              std::vector<solvers::collision::ContactPoint<d>>& scratch, double* clampEnergyChange,
                              int* clampsApplied);

  // Shock propagation over one island (GBF 2003; notes 1.6): bottom-up through the levels, each
  // level's bodies frozen (infinite mass) once its pairs are done; all unfrozen at the end.
  int propagateShock(int island, ImpulseMode mode, const CandidateStep& step, bool onlyContacted,
                     double* clampEnergyChange, int* clampsApplied);

  // One update of a contact stage as the island/task layer records it (systems/island_tasks.h):
  // the stages' sweeps record their updates in the thesis's order and run them as ordered tasks.
  struct SweepTask {
    enum class Kind : char { Collision, Pair, Joint, Freeze };
    Kind kind = Kind::Pair;
    int index = 0;                   // the pair (Collision, Pair) or the body (Joint, Freeze)
    int listBegin = 0, listEnd = 0;  // Joint: its pairs, in the sequence's lists
    double epsilon = 0;
    int iterations = 0;
    bool shockFriction = false;  // Pair, Joint: in shock propagation (findPairImpulse)
    long stamp = 0;  // Collision: the stamp of this check (increasing along the sequence)
  };
  // The island/task layer: the islands run at once, each island's updates as ordered tasks,
  // bitwise the one-thread result. Push-out's rounds record their own tasks through it.
  IslandTasks<SweepTask>& islandTasks() { return tasks_; }
  const IslandTasks<SweepTask>& islandTasks() const { return tasks_; }
  template <class F>
  void forEachIsland(F&& f) {
    tasks_.forEachIsland(std::forward<F>(f));
  }
  // How many consecutive updates the ordered tasks hand out together (see the definition).
  int taskGrain() const;

  // The step energy clamp (ContactSettings::stepEnergyClamp; systems/step_energy_clamp.cpp).
  // At Step II's start: each body's time-n position and kinetic energy, and whether gravity is
  // the only force on it.
  void rememberStepStart(World<d>& world);
  // After Step V's contact: every island whose bodies only gravity and contact moved, that
  // touches a static or sleeping body and whose energy rose, has its bodies' velocities and
  // angular momenta scaled by one factor that takes the rise back (all of its kinetic energy
  // at most). Returns the islands scaled; adds the kinetic energy removed to `removed`.
  int clampStepEnergyGain(World<d>& world, double& removed);

  std::vector<ContactBody<d>> bodies;
  std::vector<ContactPairState> pairs;
  solvers::contact::Islands islands;
  solvers::contact::ContactLevels levels;
  std::vector<std::pair<int, int>> graphEdges;  // (below, above): the edges `levels` came from
  // Per island: pair indices sorted by (level, index).
  std::vector<std::vector<int>> islandPairsByLevel;
  // Impulses the last collision stage applied; -1 before the first. A resting island's first
  // collision sweep is speculative on several threads only after none (see below).
  int lastCollisionImpulses = -1;
  ContactSettings settings;
  Vec<d> gravity = Vec<d>::Zero();
  // The bodies' velocities as Step III's contact started (after the joint stages of Steps II.2
  // and III.2), kept only in a scene whose joints ask for Step III's joint-and-contact
  // projection (systems/articulation.h, preStabilizeWithContacts), which starts from them.
  std::vector<VecD> stepThreeStartV;
  std::vector<solvers::contact::AngVec<d>> stepThreeStartL;

 private:
  using Sequence = TaskSequence<SweepTask>;
  // Runs one recorded update of a stage in `mode`; `lists` holds a joint solve's pairs.
  TaskCounts runTask(const SweepTask& t, ImpulseMode mode, const CandidateStep& step, const std::vector<int>& lists);
  // Adds an update to an island's sequence (it runs at once when the sequence is untracked).
  void addTask(Sequence& s, ImpulseMode mode, const CandidateStep& step, const SweepTask& task, const int* touched,
               int count);
  // Runs an island's recorded updates in `mode` (island_tasks.h); returns the impulses applied.
  int runTasks(Sequence& s, ImpulseMode mode, const CandidateStep& step);
  // The first collision sweep of an island when the last step's collision stage applied no
  // impulse (a resting pile): every pair update runs at once without applying anything, on a
  // copy of its pair state; in the sweep's order those that found nothing to apply are taken as
  // they are, and from the first that did, the rest run as ordered tasks. Until then no body has
  // changed, so each taken update saw what the sequential sweep gives it: the same result.
  // Returns the impulses applied.
  int speculativeCollisionSweep(int island, const CandidateStep& step, double* clampEnergyChange, int* clampsApplied);
  // Records the island's collision checks from position `from` on as tasks of sweep `sweep`
  // and runs them (runTasks). Returns the impulses applied.
  int runCollisionTasks(Sequence& s, int island, int sweep, const CandidateStep& step, std::size_t from);
  struct CollisionProbe {  // what one update found, on a copy of its pair's state
    ContactPairState pair;
    int impulses = 0, clamps = 0;
    double energyChange = 0;
  };
  std::vector<CollisionProbe> probes_;
  // Per pair slot (ContactPairState::manifold): the manifold the narrow phase last found for the
  // pair in (a, b) order, each point as its two witness points in their bodies' frames and its
  // normal in its owner's frame, and where the smaller body (the mover) was in the larger one's
  // frame then. Written only by an update of its own pair (whose task owns the pair's bodies);
  // invalid from the start of every step (findPairs), so nothing outlives the step.
  struct CachedPoint {
    VecD onA = VecD::Zero(), onB = VecD::Zero(), normal = VecD::Zero();
    bool normalOnA = false;  // the normal turns with A (A is a half-space), else with B
  };
  struct CachedManifold {
    bool valid = false;
    double margin = 0, reach = 0;  // the query's margin, and how much more the points cover
    Eigen::Matrix<double, d, d> relativeR = Eigen::Matrix<double, d, d>::Identity();
    VecD relativeX = VecD::Zero();
    std::vector<CachedPoint> points;
  };
  mutable std::vector<CachedManifold> manifolds_;
  void resetManifolds(std::size_t pairCount);
  IslandTasks<SweepTask> tasks_;
  int kinematicFrameBody_ = -1;            // the scene's one translating kinematic body, or -1 (pack)
  // rememberStepStart: per body, x^n, its kinetic energy at time n, and whether gravity is the
  // only force on it (no scripted motion either).
  struct StepStart {
    VecD x = VecD::Zero();
    double kinetic = 0;
    bool gravityOnly = false;
  };
  std::vector<StepStart> stepStart_;
  bool gravityOnly(World<d>& world, std::size_t i) const;

  void ensureGeometry(World<d>& world);
  std::vector<Entity> entities_;
  // Body index pairs joined by an articulation joint: never paired (sorted, first < second).
  std::vector<std::pair<int, int>> jointedPairs_;
  std::vector<std::unique_ptr<solvers::collision::PreparedGeometry<d>>> geometries_;
  // Per body: where its collision geometry's centre lies in its body frame (non-zero only for a
  // static box reaching down through the ground, solvers/collision/grounded_box.h).
  std::vector<VecD> centreShift_;
  std::unique_ptr<solvers::collision::BroadPhase<d>> broadPhase_;
  std::vector<Eigen::AlignedBox<double, d>> boxes_;
  // Takes `found` (sorted, a superset of `pairs`) as the pair list, keeping the known pairs'
  // state; recomputes the islands and the per-island level lists.
  void rebuildPairsFrom(const std::vector<std::pair<int, int>>& found);
  // Per island: its processed pairs, stably sorted by level.
  void sortIslandPairsByLevel();
  std::vector<char> infinite_;
  // growPairs' buffers: which boxes grew, and the merged pair list.
  std::vector<char> grew_;
  std::vector<std::pair<int, int>> mergedPairs_;
  std::vector<ContactPairState> freshPairs_;  // findPairs' new list
  // computeLevels' poses of each body re-advanced with its old and its new velocity.
  std::vector<std::array<solvers::collision::Pose<d>, 2>> reAdvancedPoses_;
};

}  // namespace monolith

#include "systems/contact_workspace_impl.h"
