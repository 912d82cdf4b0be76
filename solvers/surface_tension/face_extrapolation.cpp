#include "solvers/surface_tension/face_extrapolation.h"

namespace monolith::solvers {

void extrapolateToUnknownFaces(const MacLayout<2>& layout, std::vector<char> known, Eigen::VectorXd& u, int layers) {
  using Index2 = Eigen::Vector2i;
  const int nf = layout.totalFaces();
  for (int f = 0; f < nf; ++f)
    if (!known[f]) u[f] = 0;
  for (int layer = 0; layer < layers; ++layer) {
    std::vector<int> filled;
    Eigen::VectorXd next = u;
    for (int f = 0; f < nf; ++f) {
      if (known[f]) continue;
      const auto [axis, idx] = layout.faceCoord(f);
      const Index2 dims = layout.faceDims(axis);
      double sum = 0;
      int count = 0;
      for (int b = 0; b < 2; ++b)
        for (int dir : {-1, 1}) {
          Index2 m = idx;
          m[b] += dir;
          if (m[b] < 0 || m[b] >= dims[b]) continue;
          const int o = layout.faceIndex(axis, m);
          if (known[o]) sum += u[o], ++count;
        }
      if (count > 0) next[f] = sum / count, filled.push_back(f);
    }
    u = next;
    for (int f : filled) known[f] = 1;
  }
}

}  // namespace monolith::solvers
