// Step IV item 2 (thesis Sec. 4.6.1, Appendix B; notes 1.7): interpenetration resolution after
// the positions have been advanced to \hat x^{n+1}. Levels are processed from the bottom; in
// each, every body in turn is the central body c and is pushed apart from all bodies of its
// level's pairs that intersect it at once (the 6x6 / 3x3 solves of App. B, which avoid the
// messenger problem of pairwise push-out); lower levels are frozen (static outer bodies) and the
// distance is corrected gradually (fraction k/K on level iteration k). Momenta are unchanged:
// only positions and orientations move (App. B.1). Finally the velocity is reset to the
// post-collision \hat v^n plus the Step I kick, so that Step V's half kick completes the
// trapezoid update from \hat v^n (the contact impulses of Step III only served the positions).
#include <algorithm>

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
    ws.forEachIsland([&](int island) {
      std::vector<col::ContactPoint<d>> scratch;
      std::vector<con::PushOutOuter<d>> outers;
      std::vector<int> outerIndex;
      const auto& list = ws.islandPairsByLevel[island];
      col::ContactQuery query;
      for (std::size_t begin = 0; begin < list.size();) {
        const int level = ws.pairs[list[begin]].level;
        std::size_t end = begin;
        while (end < list.size() && ws.pairs[list[end]].level == level) ++end;
        for (int li = 1; li <= s.pushOutLevelIterations; ++li) {
          const double fraction = double(li) / double(s.pushOutLevelIterations);
          for (int c : ws.islands.members[island]) {
            if (ws.levels.levelOf[c] != level) continue;
            ContactBody<d>& C = ws.bodies[c];
            if (C.infinite()) continue;
            for (int iteration = 0; iteration < s.pushOutBodyIterations; ++iteration) {
              outers.clear();
              outerIndex.clear();
              for (std::size_t k = begin; k < end; ++k) {
                const ContactPairState& p = ws.pairs[list[k]];
                if (p.a != c && p.b != c) continue;
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
                out.displacement = -fraction * deepest->depth * deepest->normal;
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
              ++pushes[island];
            }
          }
        }
        for (int m : ws.islands.members[island])
          if (ws.levels.levelOf[m] == level) ws.bodies[m].frozen = true;
        begin = end;
      }
      for (int m : ws.islands.members[island]) ws.bodies[m].frozen = false;
    });
  }

  // Deepest remaining overlap of the pairs in contact, relative to the smaller body's size.
  double worst = 0, worstDepth = 0;
  std::vector<col::ContactPoint<d>> scratch;
  for (const ContactPairState& p : ws.pairs) {
    if (!p.processed) continue;
    const ContactBody<d>& A = ws.bodies[p.a];
    const ContactBody<d>& B = ws.bodies[p.b];
    scratch.clear();
    col::findContacts(*A.geometry, A.candidate, *B.geometry, B.candidate, col::ContactQuery{}, scratch);
    const double size = std::min(A.geometry->minimumSize(), B.geometry->minimumSize());
    for (const auto& cp : scratch) {
      worstDepth = std::max(worstDepth, cp.depth);
      worst = std::max(worst, cp.depth / size);
    }
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
