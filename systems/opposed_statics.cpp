#include "systems/opposed_statics.h"

#include "solvers/collision/face_escape.h"

namespace monolith {

namespace col = solvers::collision;
namespace con = solvers::contact;

template <int d>
void escapeOpposedStatics(const std::vector<ContactBody<d>>& bodies, const ContactBody<d>& central, double fraction,
                          double tolerance, std::vector<con::PushOutOuter<d>>& outers, std::vector<int>& outerIndex) {
  using VecD = Eigen::Matrix<double, d, 1>;
  // Nothing to do unless two static bodies touch c (the common case: every solve of a later
  // round comes here), so that is found first, without allocating.
  int staticBodies = 0;
  for (std::size_t k = 0; k < outers.size(); ++k)
    if (bodies[outerIndex[k]].isStatic && (k == 0 || outerIndex[k - 1] != outerIndex[k])) ++staticBodies;
  if (staticBodies < 2) return;
  // The statics in order of their (consecutive) outers, each with its outers' push directions.
  struct Static {
    int body;
    std::vector<VecD> directions;
  };
  std::vector<Static> statics;
  for (std::size_t k = 0; k < outers.size(); ++k) {
    if (!outers[k].isStatic) continue;
    if (statics.empty() || statics.back().body != outerIndex[k]) statics.push_back({outerIndex[k], {}});
    statics.back().directions.push_back(outers[k].displacement.normalized());
  }
  const auto opposed = [&](const Static& a, const Static& b) {
    for (const VecD& u : a.directions)
      for (const VecD& v : b.directions)
        if (u.dot(v) < -0.5) return true;
    return false;
  };
  std::vector<char> replaced(statics.size(), 0);
  std::vector<VecD> avoid;
  for (std::size_t pass = 0; pass < statics.size(); ++pass) {
    int chosen = -1;
    col::ContactPoint<d> best;
    for (std::size_t i = 0; i < statics.size(); ++i) {
      const ContactBody<d>& O = bodies[statics[i].body];
      if (replaced[i] || !O.isStatic || O.geometry->geometry().type != col::GeometryType::Box) continue;
      avoid.clear();
      for (std::size_t j = 0; j < statics.size(); ++j) {
        if (j == i || !bodies[statics[j].body].isStatic || !opposed(statics[i], statics[j])) continue;
        avoid.insert(avoid.end(), statics[j].directions.begin(), statics[j].directions.end());
      }
      if (avoid.empty()) continue;
      col::ContactPoint<d> escape;
      if (!col::escapeThroughBoxFace<d>(*O.geometry, O.candidate, *central.geometry, central.candidate, avoid, escape)) continue;
      if (escape.depth <= tolerance) continue;
      if (chosen < 0 || escape.depth < best.depth) chosen = static_cast<int>(i), best = escape;
    }
    if (chosen < 0) return;
    replaced[chosen] = 1;
    // The chosen box's outers become its one escape push; its direction list becomes that
    // push's (an escape is within 120 degrees of what opposed it, so what it opposes changes).
    const int o = statics[chosen].body;
    std::size_t first = 0;
    while (outerIndex[first] != o) ++first;
    std::size_t last = first;
    while (last < outers.size() && outerIndex[last] == o) ++last;
    con::PushOutOuter<d> out = outers[first];
    out.r = best.point - central.x0;
    out.q = best.point - bodies[o].x0;
    out.displacement = -fraction * best.depth * best.normal;
    outers.erase(outers.begin() + first + 1, outers.begin() + last);
    outerIndex.erase(outerIndex.begin() + first + 1, outerIndex.begin() + last);
    outers[first] = out;
    statics[chosen].directions.assign(1, out.displacement.normalized());
  }
}

template void escapeOpposedStatics<2>(const std::vector<ContactBody<2>>&, const ContactBody<2>&, double, double,
                                      std::vector<con::PushOutOuter<2>>&, std::vector<int>&);
template void escapeOpposedStatics<3>(const std::vector<ContactBody<3>>&, const ContactBody<3>&, double, double,
                                      std::vector<con::PushOutOuter<3>>&, std::vector<int>&);

}  // namespace monolith
