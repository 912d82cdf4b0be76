#pragma once
// Shape measures of a closed 2-D front, for the rising-bubble runs (thesis Sec. 6.4.5: "the
// interface location at the top middle and bottom middle" of the bubble) and metrics.csv.
#include <Eigen/Core>

#include "solvers/surface_tension/front.h"

namespace monolith::solvers {

struct FrontShape {
  double area = 0, length = 0;
  Eigen::Vector2d centroid = Eigen::Vector2d::Zero();  // of the enclosed region
  double circularity = 0;  // 2 sqrt(pi A) / L: 1 for a circle, smaller for any other shape
  // Highest and lowest crossing of the vertical line through the centroid ("top middle" and
  // "bottom middle"; NaN if the front does not cross it).
  double top = 0, bottom = 0;
};

FrontShape measureFront(const Front2& front);

}  // namespace monolith::solvers
