#pragma once
// Push-out's rounds (Step IV item 2: thesis Sec. 4.6.1 and App. B, with the additions listed
// below): the whole interpenetration resolution of one step's rigid bodies, from the first
// measurement to the joint solves of jams. It knows nothing of entities or components: it
// works on a host that holds the step's bodies and pairs (ResolveInterpenetration's adapter over
// the contact workspace, systems/push_out_host.h), and returns what it did.
//
// The thesis's round (the first): levels are processed from the bottom; in each, every body in
// turn is the central body c and is pushed apart from all bodies of its level's pairs that
// intersect it at once (the 6x6 / 3x3 solves of App. B, push_out.h, which avoid the messenger
// problem of pairwise push-out); lower levels are frozen (static outer bodies) and the distance
// is corrected gradually (fraction k/K on level iteration k). Only positions and orientations
// move (App. B.1).
//
// Not in the thesis (docs/architecture.md "Push-out of new overlaps", "Push-out in rounds",
// "Jams pushed apart at once"):
// - with ContactSettings::pushOutNewOverlaps every pair of the broad phase is taken, not only
//   those Step II processed, and a pair that overlaps before push-out starts ties its two bodies
//   into one level: a pair that did not touch at the candidate poses in Step II can overlap after
//   Step III has changed a body's velocity or after push-out has moved a body out of another one
//   (in sliver_shards a shard was pushed through the ground plane this way, 147 % of its
//   thickness);
// - later rounds (pushOutRounds) push apart the bodies of pairs the broad phase grown after a
//   round adds, of pairs a round pushed deeper and of pairs still deeper than
//   pushOutRoundOverlap; they tie the bodies of their pairs into one level and take every
//   overlapping point of a static, and a round that leaves what it touched deeper is undone;
// - what the rounds leave deeper than pushOutJointOverlap (a jam) is pushed apart at once
//   (joint_push_out.h), with more rings of neighbours while it stays deeper than
//   pushOutJointRegrowOverlap.
//
// The host (a template parameter of run; every call is on the thread that calls run, except
// where forEachIsland runs islands at once):
//   bodies        vector of bodies with: geometry (->minimumSize(), ->boundingRadius()),
//                 candidate (the collision pose the pairs are tested at), x0, q0 (base pose),
//                 inertia0, inverseInertia0 (world, at q0), mass, frozen, infinite(),
//                 inverseMass();
//   pairs         vector of pairs with a, b, processed (Step II), level (the contact graph's);
//   islands, levels, graphEdges   the step's Islands, ContactLevels and their (below, above)
//                 edges (contact_graph.h);
//   setBasePose(body, x, q)       a body moved to (x, q): its base and candidate pose there;
//   rotated(q, theta)             q turned by the world rotation vector theta;
//   growPairs()                   the broad phase grown to the candidate poses; returns the
//                                 pairs added (new pairs are merged into the sorted list);
//   forEachIsland(f), startOrder(order, island, bound), addOrdered(order, frozen, touched, n),
//   memberIndex(body)             the islands run at once, each as ordered tasks
//                                 (solvers/parallel/ordered_tasks.h): bitwise the one-thread result;
//   escapeOpposedStatics(central, fraction, tolerance, outers, outerIndex)
//                                 a later round's guard against two statics pushing a body in
//                                 opposite directions (systems/opposed_statics.h).
#include <Eigen/Geometry>
#include <type_traits>
#include <utility>
#include <vector>

#include "solvers/collision/narrow_phase.h"
#include "solvers/contact/contact_graph.h"
#include "solvers/contact/contact_settings.h"
#include "solvers/contact/joint_push_out.h"
#include "solvers/contact/push_out.h"
#include "solvers/parallel/ordered_tasks.h"

namespace monolith::solvers::contact {

// What one step's push-out did (the metrics of the same names, systems/interpenetration.cpp).
struct PushOutReport {
  int solves = 0;             // central-body solves, all rounds
  int newOverlaps = 0;        // pairs not processed in Step II that overlap when push-out starts
  int rounds = 0;             // rounds kept
  int roundsUndone = 0;       // later rounds undone (they left what they touched deeper)
  int jointPasses = 0;        // joint passes over jams that were kept
  int jointRegrowths = 0;     // joint solves again with more rings
  int overlapsFoundAfter = 0; // pairs the last growth added that overlap
  int pairsAdded = 0;         // pairs the grown broad phase added
  double maxPenetration = 0;       // deepest overlap of any pair at the end (m)
  double maxPenetrationRatio = 0;  // and over the smaller body's size
};

template <int d>
class PushOutRounds {
 public:
  // The orientation of a body's pose (components/rigid_body.h's Orientation<d>).
  using Orientation = std::conditional_t<d == 3, Eigen::Quaterniond, double>;

  // Pushes the host's bodies apart from where they are (their base and candidate poses).
  template <class Host>
  PushOutReport run(Host& host, const ContactSettings& settings);

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
    // The plan is recorded and run in chunks, one running while the next is recorded (pushApart):
    // the chunks' dependencies are recorded into these two in turn.
    parallel::OrderedTasks order, nextOrder;
  };

 private:
  // One central-body task of a plan: the body pushed apart from the bodies of its pairs on its
  // level (App. B), pushOutBodyIterations times at most. Returns the solves.
  template <class Host>
  int pushCentral(Host& host, const ContactSettings& s, const PushTask& task, const std::vector<int>& centralPairs,
                  bool focused);
  // A plan is recorded in about this many chunks, each of at least kPushChunkTasks tasks.
  static constexpr std::size_t kPushChunks = 4, kPushChunkTasks = 256;
  // Per pair: its deepest overlap (m) and that over the smaller body's size, as last measured.
  // `which(k)` picks the pairs measured again; the others keep their values.
  template <class Host, typename Which>
  void measurePairs(const Host& host, Which&& which);
  std::vector<double> depth_, ratio_;
  // Per pair: whether it overlaps though Step II did not process it (newOverlap_); returns how
  // many do.
  template <class Host>
  int markNewOverlaps(const Host& host, const ContactSettings& s);
  // The levels push-out runs by (pairLevel_ per pair): the contact graph's, or with new overlaps
  // those of its copy with an edge both ways per new overlap (newOverlap_, which a later round
  // also sets for the pairs it ties, tie_).
  template <class Host>
  const ContactLevels& pushLevels(const Host& host, int newOverlaps);
  // One round of push-out over the islands marked in active_; returns the central-body solves.
  // focused: only the pairs with a body in focus_ (the rounds after the first).
  template <class Host>
  int pushApart(Host& host, const ContactSettings& s, const ContactLevels& levels, bool focused);
  struct SavedPose {
    int body;
    Vec<d> x;
    Orientation q;
  };
  std::vector<SavedPose> savedPoses_;  // a later round's bodies before it, to undo it
  std::vector<IslandPlan> plans_;
  std::vector<char> active_;      // per island: pushed apart in this round
  std::vector<char> focus_;       // per body: worked on in the next round
  std::vector<char> partner_;     // per body: a dynamic neighbour of a focus body
  std::vector<char> tie_;         // per pair of two dynamic bodies: one level in the next round
  std::vector<std::pair<int, int>> knownPairs_;  // the pairs before a round's growth
  std::vector<double> knownDepth_, knownRatio_;  // and their measurements
  std::vector<int> knownIndex_;                  // per pair after the growth: its index before, or -1
  std::vector<char> moved_;       // per body: in an island push-out worked on
  // The pairs whose depths growAndMeasure measured again: a body in moved_, or new.
  template <class Host>
  bool movedOrNew(const Host& host, std::size_t k) const;
  // After bodies in moved_ moved: the broad phase grown where they are, the depths carried over
  // and measured again (movedOrNew); returns the pairs added.
  template <class Host>
  int growAndMeasure(Host& host);
  // The jam left after the rounds pushed apart at once (joint_push_out.h), pass by pass while
  // each leaves its pairs shallower. Returns the passes kept; adds to newPairs. The jam is the
  // deep pairs' bodies and `rings` rings of their dynamic neighbours.
  template <class Host>
  int pushJamsApart(Host& host, const ContactSettings& s, int rings, int& newPairs);
  static constexpr int kJointPasses = 16;    // linearisations, at most
  static constexpr int kJointHalvings = 3;   // of a pass's step that leaves the jam no shallower
  static constexpr int kJointRings = 2;      // neighbours of neighbours of the deep pairs' bodies
  static constexpr int kJointRegrowths = 3;  // solves again with 4, 8, 16 rings, at most
  static constexpr int kJointSweeps = 2000;  // Gauss-Seidel sweeps per linearisation, at most
  std::vector<char> jamRing_, jamNext_;      // the bodies a ring grows from, and those it adds
  std::vector<int> jamIndex_;  // per body: its index in the joint solve, or -1 (a fixed partner)
  std::vector<JointBody<d>> jamBodies_;
  std::vector<JointPoint<d>> jamPoints_;
  std::vector<JointMove<d>> jamMoves_;
  std::vector<collision::ContactPoint<d>> jamContacts_;  // one pair's narrow phase, kept
  std::vector<SavedPose> passStart_;  // the jam's bodies and their poses before a pass, to undo it
  std::vector<char> newOverlap_;  // per pair: not processed in Step II, yet overlapping in push-out (or tied)
  std::vector<int> pairLevel_;    // per pair: its level in push-out
  std::vector<std::pair<int, int>> edges_;
  ContactLevels pushLevels_;
};

}  // namespace monolith::solvers::contact
