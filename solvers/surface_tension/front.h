#pragma once
// A Lagrangian front (thesis Sec. 6.3.1): points and simplices, dimension-generic in its layout
// (segments of 2 points in 2-D, triangles of 3 in 3-D), with the 2-D operations of Ch. 6 on
// closed polylines: the curvature (6.34), the surface-tension force (6.35/6.36) and its
// normal-only derivative factor C (Sec. 6.3.2), and the front-tracking remeshing of Sec. 6.3.1.
// Orientation: counter-clockwise loops enclose the "inside" phase; the outward normal of a
// segment is R t with R = [[0, 1], [-1, 0]] (thesis Sec. 6.3.5).
// Knows nothing of entities or grids.
#include <Eigen/Core>
#include <array>
#include <vector>

namespace monolith::solvers {

template <int d>
struct Front {
  using Vec = Eigen::Matrix<double, d, 1>;
  std::vector<Vec> points;
  std::vector<std::array<int, d>> elements;  // segments (2-D) or triangles (3-D), point indices

  int pointCount() const { return static_cast<int>(points.size()); }
  int elementCount() const { return static_cast<int>(elements.size()); }
};

using Front2 = Front<2>;

// Closed polygon through `points` in order (segment k joins k and k+1 mod n).
Front2 closedPolyline(const std::vector<Eigen::Vector2d>& points);
// r(theta) = radius (1 + epsilon cos(m theta)) about `centre`, n points, counter-clockwise, the first
// at theta = offset (half a step by default: no point on the axes through the centre).
Front2 perturbedCircle(const Eigen::Vector2d& centre, double radius, double epsilon, int m, int n,
                       double offset = -1);

// Per point: the two segments that meet there (previous ending at it, next starting at it);
// -1 where a point ends an open polyline. Throws std::invalid_argument if a point has more than
// one incoming or outgoing segment.
std::vector<std::array<int, 2>> pointSegments(const Front2& front);

// (kappa n)_k of eq. (6.34): the difference of the unit tangents divided by l_k = (l_{k-1/2} + l_{k+1/2}) / 2.
// Zero at the ends of an open polyline.
std::vector<Eigen::Vector2d> curvatureNormals(const Front2& front);
// f_k = sigma (t_{k+1/2} - t_{k-1/2}), eq. (6.35) (the per-segment form (6.36) summed).
std::vector<Eigen::Vector2d> surfaceTensionForces(const Front2& front, double sigma);
// Signed area enclosed (positive for counter-clockwise loops) and total length.
double enclosedArea(const Front2& front);
double frontLength(const Front2& front);

// Front-tracking remeshing (Sec. 6.3.1): while a segment is longer than maxLength it is split at
// the 4-point third-order stencil -1/16 x_{k-1} + 9/16 x_k + 9/16 x_{k+1} - 1/16 x_{k+2}; while one
// is shorter than minLength, the endpoint whose removal leaves the shorter merged segment is
// deleted. Works on closed loops (every point with one incoming and one outgoing segment); a loop
// that falls below 4 points is removed. Returns the number of points added plus removed.
int remeshClosedFront(Front2& front, double minLength, double maxLength);

// Inside test against closed loops: true if x lies inside (even-odd rule; the half-open crossing
// rule a <= c < b is used everywhere, so grid-line crossings and inside tests agree).
bool insideFront(const Front2& front, const Eigen::Vector2d& x);

}  // namespace monolith::solvers
