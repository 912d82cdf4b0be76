// Step IV item 2 (thesis Sec. 4.6.1, Appendix B; notes 1.7): interpenetration resolution after
// the positions have been advanced to \hat x^{n+1}. Levels are processed from the bottom; in
// each, every body in turn is the central body c and is pushed apart from all bodies of its
// level's pairs that intersect it at once (the 6x6 / 3x3 solves of App. B, which avoid the
// messenger problem of pairwise push-out); lower levels are frozen (static outer bodies) and the
// distance is corrected gradually (fraction k/K on level iteration k). Momenta are unchanged:
// only positions and orientations move (App. B.1). Finally the velocity is reset to the
// post-collision \hat v^n plus the Step I kick, so that Step V's half kick completes the
// trapezoid update from \hat v^n (the contact impulses of Step III only served the positions).
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <utility>

#include "solvers/contact/push_out.h"
#include "systems/rigid_contact.h"

namespace monolith {

namespace col = solvers::collision;
namespace con = solvers::contact;

namespace {

template <int d>
void setBasePose(ContactBody<d>& b, const Eigen::Matrix<double, d, 1>& x, const Orientation<d>& q) {
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

}  // namespace

template <int d>
void ResolveInterpenetration<d>::run(World<d>& world, StepContext& ctx) {
  (void)world;
  ContactWorkspace<d>& ws = *this->ws_;
  if (ws.bodies.empty()) return;
  for (auto& b : ws.bodies) setBasePose<d>(b, b.body->x, b.body->orientation);
  const ContactSettings& s = ws.settings;
  std::vector<int> pushes(ws.islands.members.size(), 0);

  if (s.pushOut) {
    if (plans_.size() < ws.islands.members.size()) plans_.resize(ws.islands.members.size());
    ws.forEachIsland([&](int island) {
      // Recorded first as ordered tasks (one per central body and level iteration, then the
      // level's freezes) and run on the arena's threads with the sequential result, as the
      // contact sweeps are (systems/contact_workspace.h). Each island has its own plan slot.
      IslandPlan& plan = plans_[island];
      auto& tasks = plan.tasks;
      auto& centralPairs = plan.centralPairs;
      auto& order = plan.order;
      auto& touched = plan.touched;
      auto& levelMembers = plan.levelMembers;
      auto& bodyPair = plan.bodyPair;
      auto& range = plan.range;
      tasks.clear();
      centralPairs.clear();
      ws.startOrder(order, island);
      const auto& members = ws.islands.members[island];
      auto& frozen = plan.frozen;
      frozen.assign(members.size(), 0);
      const auto& list = ws.islandPairsByLevel[island];
      for (std::size_t begin = 0; begin < list.size();) {
        const int level = ws.pairs[list[begin]].level;
        std::size_t end = begin;
        while (end < list.size() && ws.pairs[list[end]].level == level) ++end;
        // This island's bodies on the level, ascending (a level is one component of the contact
        // graph), and each one's pairs on the level in order: found by grouping, since scanning
        // the level's pairs for every body made large piles (a cycle of many bodies) quadratic.
        levelMembers.clear();
        for (int c : ws.levels.nodes[level])
          if (ws.islands.islandOf[c] == island) levelMembers.push_back(c);
        bodyPair.clear();
        for (std::size_t k = begin; k < end; ++k) {
          const ContactPairState& p = ws.pairs[list[k]];
          bodyPair.emplace_back(p.a, list[k]);
          if (p.b != p.a) bodyPair.emplace_back(p.b, list[k]);
        }
        std::stable_sort(bodyPair.begin(), bodyPair.end(),
                         [](const auto& x, const auto& y) { return x.first < y.first; });
        range.assign(levelMembers.size(), {0, 0});
        {
          std::size_t g = 0;
          for (std::size_t m = 0; m < levelMembers.size(); ++m) {
            while (g < bodyPair.size() && bodyPair[g].first < levelMembers[m]) ++g;
            range[m].first = static_cast<int>(centralPairs.size());
            for (; g < bodyPair.size() && bodyPair[g].first == levelMembers[m]; ++g)
              centralPairs.push_back(bodyPair[g].second);
            range[m].second = static_cast<int>(centralPairs.size());
          }
        }
        for (int li = 1; li <= s.pushOutLevelIterations; ++li) {
          const double fraction = double(li) / double(s.pushOutLevelIterations);
          for (std::size_t m = 0; m < levelMembers.size(); ++m) {
            const int c = levelMembers[m];
            touched.assign(1, c);
            for (int q = range[m].first; q < range[m].second; ++q) {
              const ContactPairState& p = ws.pairs[centralPairs[q]];
              touched.push_back(p.a == c ? p.b : p.a);
            }
            tasks.push_back({c, -1, range[m].first, range[m].second, fraction});
            ws.addOrdered(order, frozen, touched.data(), static_cast<int>(touched.size()));
          }
        }
        for (int m : levelMembers) {
          tasks.push_back({-1, m, 0, 0, 0});
          ws.addOrdered(order, frozen, &m, 1);
          frozen[ws.memberIndex(m)] = 1;
        }
        begin = end;
      }
      auto& solves = plan.solves;
      solves.assign(tasks.size(), 0);
      order.run([&](int t) {
        const PushTask& task = tasks[t];
        if (task.central < 0) {
          ws.bodies[task.frozenBody].frozen = true;
          return;
        }
        thread_local std::vector<col::ContactPoint<d>> scratch;
        thread_local std::vector<con::PushOutOuter<d>> outers;
        thread_local std::vector<int> outerIndex;
        const col::ContactQuery query;
        const int c = task.central;
        ContactBody<d>& C = ws.bodies[c];
        if (C.infinite()) return;
        int count = 0;
        for (int iteration = 0; iteration < s.pushOutBodyIterations; ++iteration) {
          outers.clear();
          outerIndex.clear();
          for (int q = task.begin; q < task.end; ++q) {
            const ContactPairState& p = ws.pairs[centralPairs[q]];
            const int o = p.a == c ? p.b : p.a;
            ContactBody<d>& O = ws.bodies[o];
            scratch.clear();
            // Normal out of c towards o.
            col::findContacts(*O.geometry, O.candidate, *C.geometry, C.candidate, query, scratch);
            const col::ContactPoint<d>* deepest = nullptr;
            for (const auto& cp : scratch)
              if (cp.depth > s.pushOutTolerance && (!deepest || cp.depth > deepest->depth)) deepest = &cp;
            if (!deepest) continue;
            con::PushOutOuter<d> out;
            out.isStatic = O.infinite();
            out.r = deepest->point - C.x0;
            out.q = deepest->point - O.x0;
            out.mass = O.mass;
            out.inertia = O.inertia0;
            // d_o: from the point on c's surface to the point on o's surface (App. B.1).
            out.displacement = -task.fraction * deepest->depth * deepest->normal;
            outers.push_back(out);
            outerIndex.push_back(o);
          }
          if (outers.empty()) break;
          con::PushOutCentral<d> central;
          central.mass = C.mass;
          central.inertia = C.inertia0;
          central.lengthScale = C.geometry->boundingRadius();
          const con::PushOutResult<d> r = con::solvePushOut(central, outers);
          setBasePose<d>(C, C.x0 + r.centralDisplacement, rotatedBy<d>(C.q0, r.centralRotation));
          for (std::size_t k = 0; k < outers.size(); ++k) {
            ContactBody<d>& O = ws.bodies[outerIndex[k]];
            if (O.infinite()) continue;
            setBasePose<d>(O, O.x0 + r.outerDisplacements[k], rotatedBy<d>(O.q0, r.outerRotations[k]));
          }
          ++count;
        }
        if (count) solves[t] = count;
      });
      for (int n : solves) pushes[island] += n;
      for (int m : members) ws.bodies[m].frozen = false;
    });
  }

  // Deepest remaining overlap of the pairs in contact, relative to the smaller body's size.
  // Per pair in parallel (the queries only read), then the largest: a maximum does not depend on
  // the order it is taken in.
  std::vector<double> pairDepth(ws.pairs.size(), 0.0), pairRatio(ws.pairs.size(), 0.0);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, ws.pairs.size(), 64), [&](const tbb::blocked_range<std::size_t>& range) {
    thread_local std::vector<col::ContactPoint<d>> scratch;
    for (std::size_t k = range.begin(); k != range.end(); ++k) {
      const ContactPairState& p = ws.pairs[k];
      if (!p.processed) continue;
      const ContactBody<d>& A = ws.bodies[p.a];
      const ContactBody<d>& B = ws.bodies[p.b];
      scratch.clear();
      col::findContacts(*A.geometry, A.candidate, *B.geometry, B.candidate, col::ContactQuery{}, scratch);
      const double size = std::min(A.geometry->minimumSize(), B.geometry->minimumSize());
      for (const auto& cp : scratch) {
        pairDepth[k] = std::max(pairDepth[k], cp.depth);
        pairRatio[k] = std::max(pairRatio[k], cp.depth / size);
      }
    }
  });
  double worst = 0, worstDepth = 0;
  for (std::size_t k = 0; k < ws.pairs.size(); ++k) {
    worstDepth = std::max(worstDepth, pairDepth[k]);
    worst = std::max(worst, pairRatio[k]);
  }

  for (auto& b : ws.bodies) {
    if (b.isStatic || b.kinematic) continue;
    b.v = b.vCollided + b.dv;
    b.L = b.LCollided + b.dL;
  }
  ws.unpack(true);
  int total = 0;
  for (int n : pushes) total += n;
  ctx.diagnostics.set("push_out_solves", total);
  ctx.diagnostics.set("max_penetration", worstDepth);
  ctx.diagnostics.set("max_penetration_ratio", worst);
}

template class ResolveInterpenetration<2>;
template class ResolveInterpenetration<3>;

}  // namespace monolith
