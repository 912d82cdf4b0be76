#pragma once
// Sampled signed distance fields of closed boundaries (negative inside), for level-set obstacles
// built from a polygon (2-D) or a triangle mesh (3-D) instead of given sample by sample. The
// samples cover the boundary's bounding box plus `margin` samples on every side, so every
// boundary sample lies at least that far outside.
#include <Eigen/Core>
#include <vector>

namespace monolith::solvers {

template <int d>
struct SampledField {
  Eigen::Matrix<double, d, 1> origin;  // position of sample 0
  Eigen::Matrix<int, d, 1> samples;    // per axis
  std::vector<double> values;          // x fastest
  double sampleCount() const { return samples.template cast<double>().prod(); }
};

// The lattice origin + i * spacing that covers the points' box plus `margin` samples (values
// not yet allocated: callers check sampleCount() first; counts beyond 2^30 per axis are capped).
template <int d>
SampledField<d> latticeAround(const std::vector<Eigen::Matrix<double, d, 1>>& points, double spacing, int margin);

// Signed distance to a closed polygon (vertices in order, either orientation; inside by the
// even-odd rule, so a self-crossing outline is inside where it winds an odd number of times).
SampledField<2> polygonDistance(const std::vector<Eigen::Vector2d>& vertices, double spacing, int margin);

// Signed distance to a closed triangle mesh: the distance to the nearest triangle, negative where
// the generalized winding number (Jacobson et al. 2013; the triangles' solid angles over 4 pi) is
// above 1/2 in magnitude, which tolerates either orientation and small holes. Cost: samples x
// triangles.
SampledField<3> meshDistance(const std::vector<Eigen::Vector3d>& vertices, const std::vector<int>& triangles,
                             double spacing, int margin);

}  // namespace monolith::solvers
