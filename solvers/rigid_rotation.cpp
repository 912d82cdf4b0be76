#include "solvers/rigid_rotation.h"

#include <Eigen/Eigenvalues>

#include <cmath>
#include <limits>
#include <stdexcept>

namespace monolith::solvers {

namespace {

constexpr double kEps = std::numeric_limits<double>::epsilon();
constexpr double kPi = 3.14159265358979323846;

// |k| <= 4 eps KE0 means the energy is already exact to rounding: no correction is required
// (Sec. 2.2.3, first remark; the same tolerance the original implementation used).
constexpr double kNoFixTolerance = 4 * kEps;
// Below this absolute energy "any energy increase ... is irrelevant" (Sec. 2.2.3); eps^2 as in the
// original implementation, so that only energies that are zero for all practical purposes skip.
constexpr double kNegligibleEnergy = kEps * kEps;
// A closed-form correction is exact in exact arithmetic; forming I^-1(q) and 1/2 L.I^-1 L after the
// rotation costs a few ulps per operation, amplified by the conditioning of I0. Residuals up to this
// relative size are rounding, not a failed solve, so we do not start fallback rotations for them.
constexpr double kSolvedTolerance = 256 * kEps;
// a = s.(L x w) is the slope dKE/d(angle) (Sec. 2.2.4). a < 16 eps KE means the locally optimal
// direction carries no usable first-order information (Sec. 2.2.3 "a/KE very small (not robust)").
constexpr double kUselessSlope = 16 * kEps;
// An extremum rotation below this angle (rad) means we already sit at the extremum along s; repeating
// it could only spin through the retry cap without changing the energy.
constexpr double kNegligibleAngle = 16 * kEps;
// A fallback direction axis x L shorter than this (relative to |axis||L|) means L is aligned with the
// principal axis to ~1e-12 rad: the energy differs from that global extremum by O(1e-24) relative,
// and the direction of the cross product would be rounding noise.
constexpr double kDegenerateSine = 1e-12;
// Principal-axis fallback retries (Sec. 2.2.4; the original code aborted past 40, we accept the
// residual instead).
constexpr int kMaxFallbackRetries = 40;

double relativeError(double KE, double KE0) { return KE0 > 0 ? (KE - KE0) / KE0 : 0.0; }

bool withinTolerance(double KE, double KE0, double relTol) {
  return std::abs(KE - KE0) <= relTol * KE0;
}

// sin(x/2)/x, with a Taylor series near 0 where the quotient loses accuracy (and is 0/0 at x = 0).
// At x < 1e-3 the first omitted term, x^6/322560, is below 1e-23: exact to double precision.
double halfSinOverX(double x) {
  if (x < 1e-3) {
    const double x2 = x * x;
    return 0.5 - x2 / 48.0 + x2 * x2 / 3840.0;
  }
  return std::sin(0.5 * x) / x;
}

// Unit vector along the part of d perpendicular to L, or a zero vector if that part is degenerate.
// The closed form of Sec. 2.2.2 dropped the term s s^T L (1 - cos e), which is valid only for
// s exactly perpendicular to L, so we re-orthogonalise instead of trusting a rounded cross product.
Eigen::Vector3d perpendicularUnit(const Eigen::Vector3d& d, const Eigen::Vector3d& L, double scale) {
  const double Lnorm = L.norm();
  if (Lnorm == 0 || !(d.norm() > kDegenerateSine * scale)) return Eigen::Vector3d::Zero();
  const Eigen::Vector3d Lhat = L / Lnorm;
  const Eigen::Vector3d s = d - d.dot(Lhat) * Lhat;
  const double sNorm = s.norm();
  if (!(sNorm > kDegenerateSine * scale)) return Eigen::Vector3d::Zero();
  return s / sNorm;
}

void rotateAboutWorldAxis(Eigen::Quaterniond& q, const Eigen::Vector3d& s, double angle) {
  q = (rotationExponential(angle * s) * q).normalized();
}

// Energy along a unit axis s perpendicular to L, Eq. (2.2):
//   KE(e) = KE cos^2 e - a sin e cos e + b sin^2 e,  a = (s x L).w,  b = 1/2 (s x L)^T I^-1 (s x L).
// The axis is flipped so that a >= 0 (the sign convention under which Sec. 2.2.3's y = sgn(...) y^
// is derived; KE'(0) = -a <= 0, so positive angles lower the energy).
struct EnergyAlongAxis {
  Eigen::Vector3d s;
  double KE, a, b;
};

EnergyAlongAxis energyAlongAxis(const BodyInertia& inertia, const Eigen::Quaterniond& q,
                                const Eigen::Vector3d& L, Eigen::Vector3d s) {
  const Eigen::Matrix3d Iinv = worldInverseInertia(inertia, q);
  const Eigen::Vector3d w = Iinv * L;
  Eigen::Vector3d sL = s.cross(L);
  double a = sL.dot(w);
  if (a < 0) {
    s = -s;
    sL = -sL;
    a = -a;
  }
  return {s, 0.5 * L.dot(w), a, 0.5 * sL.dot(Iinv * sL)};
}

// Closed-form angle reaching KE0 along the axis, Sec. 2.2.2-2.2.3 in the cancellation-free form:
// g = a^2 + 4k(c-k) (g < 0: KE0 outside the range reachable along s), p = a^2 + g + 2a sqrt(g),
// x = cos e = sqrt(p + (c+n)^2)/(2r), y^ = |sin e| = 2|k|/sqrt(p + (c-n)^2), y = sgn(k - c y^2) y^.
// This picks the root of (2.4) that vanishes with k (p_b = -sgn(a), p_c = 1), i.e. the smallest
// rotation. Returns false if KE0 is not reachable along s.
bool closedFormAngle(const EnergyAlongAxis& e, double KE0, double& angle) {
  const double k = e.KE - KE0;
  const double c = e.KE - e.b;
  const double g = e.a * e.a + 4 * k * (c - k);
  if (g < 0) return false;
  const double n = c - 2 * k;
  const double r = std::hypot(c, e.a);
  const double p = e.a * e.a + g + 2 * e.a * std::sqrt(g);
  const double x = std::sqrt(p + (c + n) * (c + n)) / (2 * r);
  const double yDenominator = std::sqrt(p + (c - n) * (c - n));
  const double yHat = yDenominator > 0 ? 2 * std::abs(k) / yDenominator : 0.0;
  const double y = (k - c * yHat * yHat) < 0 ? -yHat : yHat;
  angle = std::atan2(y, x);
  return true;
}

// Angle to the energy minimum (lower = true) or maximum along the axis. Writing (2.2) as
// KE(e) = (KE+b)/2 + r/2 cos(2e + phi) with phi = atan2(a, c), the extrema are at 2e = pi - phi
// (minimum) and 2e = -phi (maximum); with a >= 0 these are the nearest ones in the right direction.
double extremumAngle(const EnergyAlongAxis& e, bool lower) {
  const double phi = std::atan2(e.a, e.KE - e.b);
  return lower ? 0.5 * (kPi - phi) : -0.5 * phi;
}

enum class AxisResult { Solved, MovedToExtremum, Useless };

// One attempt along a candidate direction d (Sec. 2.2.2-2.2.4). With allowExtremum, an unreachable
// KE0 makes us rotate to the extremum on the side of KE0 so that the caller can retry.
AxisResult correctAlongDirection(Eigen::Quaterniond& q, const BodyInertia& inertia,
                                 const Eigen::Vector3d& L, double KE0, const Eigen::Vector3d& d,
                                 double dScale, bool requireSlope, bool allowExtremum) {
  const Eigen::Vector3d s = perpendicularUnit(d, L, dScale);
  if (s.isZero()) return AxisResult::Useless;
  const EnergyAlongAxis e = energyAlongAxis(inertia, q, L, s);
  // r = sqrt(c^2 + a^2) is the amplitude of KE(e): if it is rounding-sized the energy is constant
  // along s and neither a root nor an extremum means anything.
  if (std::hypot(e.KE - e.b, e.a) <= kUselessSlope * e.KE) return AxisResult::Useless;
  if (requireSlope && e.a < kUselessSlope * e.KE) return AxisResult::Useless;
  double angle = 0;
  if (closedFormAngle(e, KE0, angle)) {
    rotateAboutWorldAxis(q, e.s, angle);
    return AxisResult::Solved;
  }
  if (!allowExtremum) return AxisResult::Useless;
  angle = extremumAngle(e, e.KE > KE0);
  if (std::abs(angle) <= kNegligibleAngle) return AxisResult::Useless;
  rotateAboutWorldAxis(q, e.s, angle);
  return AxisResult::MovedToExtremum;
}

// Sec. 2.2.4: if KE > KE0 align L with the largest principal inertia direction (lowest energy for
// this L), otherwise with the smallest (highest energy). Returned in world coordinates.
Eigen::Vector3d fallbackPrincipalAxis(const BodyInertia& inertia, const Eigen::Quaterniond& q,
                                      bool energyTooHigh) {
  const int column = energyTooHigh ? 2 : 0;
  return q * Eigen::Vector3d(inertia.principalAxes.col(column));
}

EnergyFixReport finish(EnergyFixReport report, EnergyFixReport::Status status, double KE,
                       double KE0) {
  report.status = status;
  report.relativeErrorAfter = relativeError(KE, KE0);
  return report;
}

}  // namespace

Eigen::Matrix3d crossMatrix(const Eigen::Vector3d& a) {
  Eigen::Matrix3d m;
  m << 0, -a.z(), a.y(),
       a.z(), 0, -a.x(),
       -a.y(), a.x(), 0;
  return m;
}

Eigen::Quaterniond rotationExponential(const Eigen::Vector3d& u) {
  const double angle = u.norm();
  const Eigen::Vector3d v = halfSinOverX(angle) * u;
  return Eigen::Quaterniond(std::cos(0.5 * angle), v.x(), v.y(), v.z());
}

BodyInertia BodyInertia::fromMatrix(const Eigen::Matrix3d& I0) {
  if (!I0.allFinite()) throw std::invalid_argument("BodyInertia: inertia has non-finite entries");
  const double scale = I0.cwiseAbs().maxCoeff();
  // Inertia tensors computed from meshes carry rounding asymmetry; anything beyond 1e-10 relative
  // is a caller error (e.g. a transposed product), not rounding.
  if (scale == 0 || (I0 - I0.transpose()).cwiseAbs().maxCoeff() > 1e-10 * scale)
    throw std::invalid_argument("BodyInertia: inertia is zero or not symmetric");
  const Eigen::Matrix3d S = 0.5 * (I0 + I0.transpose());
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(S);
  if (solver.info() != Eigen::Success) throw std::invalid_argument("BodyInertia: eigensolve failed");
  const Eigen::Vector3d moments = solver.eigenvalues();  // ascending
  // The eigen-solver resolves eigenvalues only to ~eps * lambda_max; a smaller "positive" moment
  // would make I0^-1 (and thus w = I^-1 L) rounding noise.
  if (!(moments(0) > 64 * kEps * moments(2)))
    throw std::invalid_argument("BodyInertia: inertia is not positive definite");
  BodyInertia result;
  result.I0 = S;
  result.principalMoments = moments;
  result.principalAxes = solver.eigenvectors();
  // Keep the axes a proper rotation so callers may convert them into an orientation.
  if (result.principalAxes.determinant() < 0) result.principalAxes.col(2) *= -1;
  // Inverse through the eigen-decomposition: exactly symmetric and as accurate as the moments.
  result.I0inv = result.principalAxes * moments.cwiseInverse().asDiagonal() *
                 result.principalAxes.transpose();
  return result;
}

Eigen::Matrix3d worldInverseInertia(const BodyInertia& inertia, const Eigen::Quaterniond& q) {
  const Eigen::Matrix3d R = q.toRotationMatrix();
  return R * inertia.I0inv * R.transpose();
}

double rotationalKineticEnergy(const BodyInertia& inertia, const Eigen::Quaterniond& q,
                               const Eigen::Vector3d& L) {
  // Evaluated in the body frame: one rotation of L instead of forming R I0^-1 R^T.
  const Eigen::Vector3d Lbody = q.conjugate() * L;
  return 0.5 * Lbody.dot(inertia.I0inv * Lbody);
}

Eigen::Vector3d rotationIncrement(RotationOrder order, double dt, const BodyInertia& inertia,
                                  const Eigen::Quaterniond& q, const Eigen::Vector3d& L) {
  const Eigen::Matrix3d Iinv = worldInverseInertia(inertia, q);
  const Eigen::Vector3d w = Iinv * L;
  // First order ([169], Sec. 4.4.1): rotate by dt w.
  Eigen::Vector3d u = dt * w;
  if (order == RotationOrder::First) return u;
  // App. A: with L constant, w' = (I^-1)' L = I^-1 (L x w); matching the dt^2 Taylor term of
  // exp(u*) against R'' R^T gives u2 = w'/2 (Sec. 4.4.1's second-order update).
  const Eigen::Vector3d wDot = Iinv * L.cross(w);
  u += 0.5 * dt * dt * wDot;
  if (order == RotationOrder::Second) return u;
  // App. A, third-order terms: u3 = w''/6 - (w x w')/12 with w'' expanded through
  // (I^-1)' = w* I^-1 - I^-1 w*; verified against the Taylor series by the convergence tests.
  const Eigen::Vector3d u3 = w.cross(wDot) / 12.0 - Iinv * w.cross(L.cross(w)) / 6.0 +
                             Iinv * L.cross(wDot) / 6.0;
  return u + dt * dt * dt * u3;
}

Eigen::Quaterniond advanceOrientation(RotationOrder order, double dt, const BodyInertia& inertia,
                                      const Eigen::Quaterniond& q, const Eigen::Vector3d& L) {
  const Eigen::Vector3d u = rotationIncrement(order, dt, inertia, q, L);
  // Renormalise so rounding cannot accumulate into a non-rotation over many steps.
  return (rotationExponential(u) * q).normalized();
}

EnergyFixReport correctOrientationForKineticEnergy(Eigen::Quaterniond& q, const BodyInertia& inertia,
                                                   const Eigen::Vector3d& L, double KE0) {
  if (!std::isfinite(KE0) || KE0 < 0)
    throw std::invalid_argument("correctOrientationForKineticEnergy: KE0 must be finite and >= 0");
  using Status = EnergyFixReport::Status;
  EnergyFixReport report;
  double KE = rotationalKineticEnergy(inertia, q, L);
  report.relativeErrorBefore = relativeError(KE, KE0);
  if (KE0 < kNegligibleEnergy) return finish(report, Status::NegligibleEnergy, KE, KE0);
  if (withinTolerance(KE, KE0, kNoFixTolerance))
    return finish(report, Status::WithinTolerance, KE, KE0);

  // Sec. 2.2.4: the locally optimal axis s = L x w, closed form only (no extremum moves: a failure
  // here means the error is too large for this direction, not that KE0 is unreachable).
  const Eigen::Vector3d w = worldInverseInertia(inertia, q) * L;
  correctAlongDirection(q, inertia, L, KE0, L.cross(w), L.norm() * w.norm(),
                        /*requireSlope=*/true, /*allowExtremum=*/false);
  KE = rotationalKineticEnergy(inertia, q, L);
  if (withinTolerance(KE, KE0, kSolvedTolerance)) return finish(report, Status::Fixed, KE, KE0);

  // Sec. 2.2.4 fallback: s = axis x L with the max/min inertia principal axis. Rotating about it
  // moves L towards the axis, whose alignment is the global energy minimum/maximum for this |L|,
  // so a reachable KE0 is found; an unreachable one leaves us at that extremum.
  for (int attempt = 0; attempt < kMaxFallbackRetries; ++attempt) {
    const Eigen::Vector3d axis = fallbackPrincipalAxis(inertia, q, KE > KE0);
    const AxisResult result = correctAlongDirection(q, inertia, L, KE0, axis.cross(L), L.norm(),
                                                    /*requireSlope=*/false, /*allowExtremum=*/true);
    if (result == AxisResult::Useless) break;
    ++report.fallbackRotations;
    KE = rotationalKineticEnergy(inertia, q, L);
    if (withinTolerance(KE, KE0, kSolvedTolerance))
      return finish(report, Status::FixedWithFallback, KE, KE0);
  }
  return finish(report, Status::ResidualAccepted, KE, KE0);
}

}  // namespace monolith::solvers
