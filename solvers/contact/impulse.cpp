// Point impulses with restitution and Coulomb friction (thesis Sec. 2.3, 4.4-4.5; notes 1.5).
#include "solvers/contact/impulse.h"

#include <Eigen/Cholesky>
#include <cmath>

namespace monolith::solvers::contact {

template <int d>
Mat<d> impulseFactor(const ImpulseBody<d>& body) {
  // Delta v at the point = m^{-1} j + (I^{-1} (r x j)) x r = (m^{-1} delta + r*^T I^{-1} r*) j.
  const CrossMat<d> rStar = crossMatrix<d>(body.r);
  Mat<d> k = body.inverseMass * Mat<d>::Identity();
  k.noalias() += rStar.transpose() * body.inverseInertia * rStar;
  return k;
}

namespace {

template <int d>
Vec<d> tangentialPart(const Vec<d>& v, const Vec<d>& n) {
  return v - v.dot(n) * n;
}

// Frictionless impulse along n: the scalar that makes the normal relative velocity -e v_n,
// i.e. -(1+e) v_n / (n.K n); with e = -1 + eps this is eps times the inelastic impulse.
template <int d>
Vec<d> normalImpulse(const Mat<d>& K, double vn, const Vec<d>& n, double e) {
  return (-(1 + e) * vn / n.dot(K * n)) * n;
}

}  // namespace

template <int d>
Vec<d> pointImpulse(const Mat<d>& K, const Vec<d>& relativeVelocity, const Vec<d>& normal,
                    const ImpulseSettings& s) {
  const double vn = relativeVelocity.dot(normal);
  // Only approaching pairs receive an impulse (v_n = min(0, v_rel.n) would make it zero anyway
  // in the normal direction, but the sticking impulse could still act tangentially).
  if (!(vn < 0)) return Vec<d>::Zero();
  const double e = s.restitution;
  const double mu = s.friction;
  if (mu <= 0) return normalImpulse<d>(K, vn, normal, e);

  // K = K_A + K_B is SPD when at least one body is finite.
  const Eigen::LLT<Mat<d>> kSolve(K);
  const Vec<d> vt = tangentialPart<d>(relativeVelocity, normal);

  // Sticking: the impulse that leaves relative velocity -e v_n n (no slip at all).
  Vec<d> j = kSolve.solve(-e * vn * normal - relativeVelocity);
  const double jn = j.dot(normal);
  const Vec<d> jt = tangentialPart<d>(j, normal);
  if (jt.norm() > mu * jn) {
    // Sliding: j = alpha (n - mu t) with t the unit slip direction. The normal condition
    //   n.(v_rel + alpha K (n - mu t)) = -e v_n   gives   alpha = -(1+e) v_n / n.K(n - mu t).
    // Without slip (|v_t| ~ 0, the sticking impulse left the cone only through the coupling in
    // K), the direction friction opposes is the one the sticking impulse pushes against.
    const double slip = vt.norm();
    Vec<d> t;
    if (slip > 1e-12 * std::abs(vn)) {
      t = vt / slip;
    } else {
      t = -jt.normalized();
    }
    const Vec<d> direction = normal - mu * t;
    const double denominator = normal.dot(K * direction);
    if (!(denominator > 1e-12 * normal.dot(K * normal))) {
      // No sliding impulse reaches the target normal velocity (friction along K's coupling
      // would pull the bodies together, a Painleve-type configuration): drop friction.
      j = normalImpulse<d>(K, vn, normal, e);
    } else {
      j = (-(1 + e) * vn / denominator) * direction;
    }
  }

  // Friction-magnitude clamp (collisions, e != 0): friction must not create sliding, so the new
  // tangential relative speed is limited to the old one and j recomputed from the clamped
  // velocity change.
  if (s.clampFrictionMagnitude && e != 0) {
    const Vec<d> after = relativeVelocity + K * j;
    const Vec<d> afterT = tangentialPart<d>(after, normal);
    const double oldSpeed = vt.norm();
    const double newSpeed = afterT.norm();
    if (newSpeed > oldSpeed) {
      const Vec<d> clamped = after.dot(normal) * normal + afterT * (oldSpeed / newSpeed);
      j = kSolve.solve(clamped - relativeVelocity);
    }
  }
  return j;
}

template Mat<2> impulseFactor<2>(const ImpulseBody<2>&);
template Mat<3> impulseFactor<3>(const ImpulseBody<3>&);
template Vec<2> pointImpulse<2>(const Mat<2>&, const Vec<2>&, const Vec<2>&,
                                const ImpulseSettings&);
template Vec<3> pointImpulse<3>(const Mat<3>&, const Vec<3>&, const Vec<3>&,
                                const ImpulseSettings&);

}  // namespace monolith::solvers::contact
