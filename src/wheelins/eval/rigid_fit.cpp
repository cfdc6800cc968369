// Rigid fits and the mirror check (rigid_fit.hpp).
#include "wheelins/eval/rigid_fit.hpp"

#include <Eigen/SVD>
#include <cmath>

namespace wheelins::eval {
namespace {

Vec3 mean_of(const std::vector<Vec3>& p) {
  Vec3 m = Vec3::Zero();
  for (const Vec3& x : p) m += x;
  return m / static_cast<double>(p.size());
}

}  // namespace

RigidFit fit_rigid(const std::vector<Vec3>& a, const std::vector<Vec3>& b, AlignFit kind) {
  RigidFit f;
  f.points = std::min(a.size(), b.size());
  if (kind == AlignFit::kNone || a.size() != b.size() || f.points < (kind == AlignFit::kSe2 ? 2u : 3u)) return f;
  const Vec3 ma = mean_of(a), mb = mean_of(b);
  Mat3 M = Mat3::Zero();
  for (std::size_t i = 0; i < a.size(); ++i) M += (b[i] - mb) * (a[i] - ma).transpose();
  if (kind == AlignFit::kSe3) {
    const Eigen::JacobiSVD<Mat3> svd(M, Eigen::ComputeFullU | Eigen::ComputeFullV);
    const Mat3 U = svd.matrixU(), V = svd.matrixV();
    const double d = (U * V.transpose()).determinant() < 0.0 ? -1.0 : 1.0;
    f.R = U * Vec3(1.0, 1.0, d).asDiagonal() * V.transpose();
  } else {
    const double theta = std::atan2(M(1, 0) - M(0, 1), M(0, 0) + M(1, 1));
    f.R = rot_z(theta);
  }
  f.t = mb - f.R * ma;
  double ss = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i) ss += (b[i] - (f.R * a[i] + f.t)).squaredNorm();
  f.rms = std::sqrt(ss / static_cast<double>(a.size()));
  f.found = true;
  return f;
}

MirrorCheck check_mirror(const std::vector<Vec3>& a, const std::vector<Vec3>& b) {
  MirrorCheck c;
  if (a.size() != b.size() || a.size() < 2) return c;
  c.points = a.size();
  const Vec3 ma = mean_of(a), mb = mean_of(b);
  Eigen::Matrix2d N = Eigen::Matrix2d::Zero();
  double spread = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    const Eigen::Vector2d x = (a[i] - ma).head<2>(), y = (b[i] - mb).head<2>();
    N += x * y.transpose();
    spread += x.squaredNorm() + y.squaredNorm();
  }
  const double proper = std::hypot(N(0, 0) + N(1, 1), N(0, 1) - N(1, 0));
  const double reflected = std::hypot(N(0, 0) - N(1, 1), N(0, 1) + N(1, 0));
  const double n = static_cast<double>(a.size());
  c.rotation_rms = std::sqrt(std::max(0.0, spread - 2.0 * proper) / n);
  c.reflection_rms = std::sqrt(std::max(0.0, spread - 2.0 * reflected) / n);
  c.mirrored = c.points >= 10 && c.reflection_rms < 0.25 * c.rotation_rms && c.rotation_rms - c.reflection_rms > 2.0;
  return c;
}

}  // namespace wheelins::eval
