// Aligning the start of a trajectory onto a reference track (alignment.hpp).
#include "wheelins/eval/alignment.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "wheelins/math/rotation.hpp"

namespace wheelins::eval {
namespace {

Eigen::Matrix2d rot2(double a) {
  Eigen::Matrix2d R;
  R << std::cos(a), -std::sin(a), std::sin(a), std::cos(a);
  return R;
}

/// The pairs of the window: reference position, trajectory position and heading.
struct Pair {
  Vec2 g, q;
  double psi;
};

bool interpolate(const PlanarTrack& tr, double t, Vec2* p, double* psi) {
  const auto it = std::lower_bound(tr.t.begin(), tr.t.end(), t);
  if (it == tr.t.end() || (it == tr.t.begin() && *it > t)) return false;
  const std::size_t k = static_cast<std::size_t>(it - tr.t.begin());
  if (tr.t[k] == t || k == 0) {
    *p = tr.p_ne[k];
    *psi = tr.heading[k];
    return true;
  }
  const double a = (t - tr.t[k - 1]) / (tr.t[k] - tr.t[k - 1]);
  *p = (1.0 - a) * tr.p_ne[k - 1] + a * tr.p_ne[k];
  *psi = tr.heading[k - 1] + a * wrap_pi(tr.heading[k] - tr.heading[k - 1]);
  return true;
}

/// Least squares for (s, l) at theta; returns the cost and fills the solution.
double solve(const std::vector<Pair>& pairs, double theta, bool antenna, const Vec2& fixed, Vec2* s, Vec2* l) {
  const Eigen::Matrix2d R = rot2(theta);
  const int n = antenna ? 4 : 2;
  Eigen::Matrix4d A = Eigen::Matrix4d::Zero();
  Eigen::Vector4d b = Eigen::Vector4d::Zero();
  for (const Pair& p : pairs) {
    // g - R q - R C l_fixed = s + R C l
    const Eigen::Matrix2d RC = R * rot2(p.psi);
    const Vec2 y = p.g - R * p.q - (antenna ? Vec2::Zero() : Vec2(RC * fixed));
    Eigen::Matrix<double, 2, 4> J = Eigen::Matrix<double, 2, 4>::Zero();
    J.block<2, 2>(0, 0).setIdentity();
    if (antenna) J.block<2, 2>(0, 2) = RC;
    A += J.transpose() * J;
    b += J.transpose() * y;
  }
  Eigen::Vector4d x = Eigen::Vector4d::Zero();
  x.head(n) = A.topLeftCorner(n, n).ldlt().solve(b.head(n));
  *s = x.head<2>();
  *l = antenna ? Vec2(x.tail<2>()) : fixed;
  double cost = 0.0;
  for (const Pair& p : pairs) cost += (p.g - (*s + R * (p.q + rot2(p.psi) * *l))).squaredNorm();
  return cost;
}

}  // namespace

Vec2 apply_alignment(const StartAlignment& a, const Vec2& p) { return a.shift + rot2(a.yaw) * p; }

StartAlignment fit_start_alignment(const PlanarTrack& ref, const PlanarTrack& tr, const StartAlignmentOptions& o) {
  StartAlignment out;
  if (tr.heading.size() != tr.t.size() || tr.t.size() < 2 || ref.t.size() < 2) return out;
  // The reference epochs at least kMinSpacing apart: a denser reference (a 200 Hz INS
  // truth) adds epochs whose residuals are the same, and the lag-1 correlation below,
  // clamped at 0.99, would count them as independent -- the sigmas would shrink with the
  // reference's rate (by sqrt(20) from 10 Hz to 200 Hz for the same track).
  constexpr double kMinSpacing = 0.1 - 1e-6;
  std::vector<Pair> pairs;
  double travelled = 0.0, last_used = -std::numeric_limits<double>::infinity();
  bool started = false;
  Vec2 prev = Vec2::Zero();
  for (std::size_t k = 0; k < ref.t.size(); ++k) {
    Pair p;
    if (!interpolate(tr, ref.t[k], &p.q, &p.psi)) continue;
    if (started) travelled += (ref.p_ne[k] - prev).norm();
    prev = ref.p_ne[k];
    started = true;
    if (o.length > 0.0 && travelled > o.length) break;
    if (ref.t[k] < last_used + kMinSpacing) continue;
    last_used = ref.t[k];
    p.g = ref.p_ne[k];
    pairs.push_back(p);
    out.t_end = ref.t[k];
  }
  out.points = pairs.size();
  out.length = travelled;
  if (pairs.size() < 5) return out;
  // Theta over the circle (1 deg), then golden section around the best.
  Vec2 s, l;
  double best = std::numeric_limits<double>::infinity(), theta = 0.0;
  for (int k = 0; k < 360; ++k) {
    const double th = k * kDeg;
    const double c = solve(pairs, th, o.estimate_antenna, o.antenna, &s, &l);
    if (c < best) best = c, theta = th;
  }
  double a = theta - kDeg, b = theta + kDeg;
  const double phi = 0.5 * (std::sqrt(5.0) - 1.0);
  for (int it = 0; it < 60; ++it) {
    const double x1 = b - phi * (b - a), x2 = a + phi * (b - a);
    if (solve(pairs, x1, o.estimate_antenna, o.antenna, &s, &l) < solve(pairs, x2, o.estimate_antenna, o.antenna, &s, &l))
      b = x2;
    else
      a = x1;
  }
  theta = 0.5 * (a + b);
  const double cost = solve(pairs, theta, o.estimate_antenna, o.antenna, &s, &l);
  out.found = true;
  out.yaw = wrap_pi(theta);
  out.shift = s;
  out.antenna = l;
  const std::size_t n = pairs.size();
  const int params = o.estimate_antenna ? 5 : 3;
  const double dof = std::max<double>(1.0, 2.0 * static_cast<double>(n) - params);
  out.rms = std::sqrt(cost / static_cast<double>(n));
  // The residuals' correlation along the window (a drifting trajectory's are smooth).
  std::vector<Vec2> r(n);
  const Eigen::Matrix2d R = rot2(theta);
  for (std::size_t k = 0; k < n; ++k) r[k] = pairs[k].g - (s + R * (pairs[k].q + rot2(pairs[k].psi) * l));
  double c0 = 0.0, c1 = 0.0;
  for (std::size_t k = 0; k < n; ++k) c0 += r[k].squaredNorm();
  for (std::size_t k = 1; k < n; ++k) c1 += r[k].dot(r[k - 1]);
  const double rho = c0 > 0.0 ? std::clamp(c1 / c0, 0.0, 0.99) : 0.0;
  const double inflation = (1.0 + rho) / (1.0 - rho);
  const double sigma2 = cost / dof * inflation;
  // Curvature in theta by central differences of the cost.
  const double h = 1e-4;
  Vec2 s2, l2;
  const double cp = solve(pairs, theta + h, o.estimate_antenna, o.antenna, &s2, &l2);
  const double cm = solve(pairs, theta - h, o.estimate_antenna, o.antenna, &s2, &l2);
  const double curv = (cp - 2.0 * cost + cm) / (h * h);  // d2(cost)/dtheta2 = 2 * information * sigma2
  out.yaw_sigma = curv > 0.0 ? std::sqrt(2.0 * sigma2 / curv) : std::numeric_limits<double>::infinity();
  if (o.estimate_antenna) {
    // The antenna's sigma from the normal matrix at theta.
    Eigen::Matrix4d A = Eigen::Matrix4d::Zero();
    for (const Pair& p : pairs) {
      Eigen::Matrix<double, 2, 4> J;
      J.block<2, 2>(0, 0).setIdentity();
      J.block<2, 2>(0, 2) = R * rot2(p.psi);
      A += J.transpose() * J;
    }
    const Eigen::Matrix4d P = A.inverse() * sigma2;
    out.antenna_sigma = Vec2(std::sqrt(std::max(0.0, P(2, 2))), std::sqrt(std::max(0.0, P(3, 3))));
  }
  return out;
}

}  // namespace wheelins::eval
