#pragma once
// The contact workspace as push-out's host (solvers/contact/push_out_rounds.h lists what a host
// provides): the step's bodies, pairs, islands and levels, and the operations on them that need
// the workspace (the broad phase, a body's world inertia at a pose) or its island/task layer
// (systems/island_tasks.h: the islands at once, each as ordered tasks).
#include <array>
#include <vector>

#include "systems/contact_workspace.h"
#include "systems/opposed_statics.h"

namespace monolith {

template <int d>
class PushOutHost {
 public:
  explicit PushOutHost(ContactWorkspace<d>& ws)
      : bodies(ws.bodies), pairs(ws.pairs), islands(ws.islands), levels(ws.levels), graphEdges(ws.graphEdges), ws_(ws) {}

  std::vector<ContactBody<d>>& bodies;
  const std::vector<ContactPairState>& pairs;
  const solvers::contact::Islands& islands;
  const solvers::contact::ContactLevels& levels;
  const std::vector<std::pair<int, int>>& graphEdges;

  // A body moved to (x, q): its base pose, world inertia there, and its candidate pose the same
  // (push-out moves bodies, not velocities).
  static void setBasePose(ContactBody<d>& b, const Eigen::Matrix<double, d, 1>& x, const Orientation<d>& q) {
    b.x0 = x;
    b.q0 = q;
    if constexpr (d == 3) b.R0 = q.toRotationMatrix();
    else b.R0 = Eigen::Rotation2Dd(q).toRotationMatrix();
    if constexpr (d == 3) {
      b.inverseInertia0 = b.R0 * b.body->inertiaBodyInverse * b.R0.transpose();
      b.inertia0 = b.R0 * b.body->inertiaBody * b.R0.transpose();
    }
    b.candidate.x = b.x0;
    b.candidate.R = b.R0;
  }
  void setBasePose(int body, const Eigen::Matrix<double, d, 1>& x, const Orientation<d>& q) {
    setBasePose(bodies[body], x, q);
  }
  static Orientation<d> rotated(const Orientation<d>& q, const solvers::contact::AngVec<d>& theta) {
    return rotatedBy<d>(q, theta);
  }
  // The broad phase grown to where push-out has put the bodies (their candidate poses).
  int growPairs() {
    return ws_.growPairs([](const ContactBody<d>& b) { return std::array<solvers::collision::Pose<d>, 1>{b.candidate}; });
  }
  // The island/task layer's (systems/island_tasks.h), with the contact stages' block size.
  template <class F>
  void forEachIsland(F&& f) {
    ws_.islandTasks().forEachIsland(std::forward<F>(f));
  }
  void startOrder(solvers::parallel::OrderedTasks& order, int island, std::size_t taskBound) const {
    ws_.islandTasks().startOrder(order, island, taskBound, ws_.taskGrain());
  }
  void addOrdered(solvers::parallel::OrderedTasks& order, const std::vector<char>& frozen, const int* touched,
                  int count) const {
    ws_.islandTasks().addOrdered(order, frozen, touched, count);
  }
  int memberIndex(int body) const { return ws_.islandTasks().memberIndex(body); }
  void escapeOpposedStatics(int central, double fraction, double tolerance,
                            std::vector<solvers::contact::PushOutOuter<d>>& outers, std::vector<int>& outerIndex) const {
    monolith::escapeOpposedStatics<d>(bodies, bodies[central], fraction, tolerance, outers, outerIndex);
  }

 private:
  ContactWorkspace<d>& ws_;
};

}  // namespace monolith
