// The level fit of level.hpp.
#include "wheelins/survey/level.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include "wheelins/survey/format.hpp"

namespace wheelins::survey {

double angle_deg(const Vec3& a, const Vec3& b) {
  const double c = std::clamp(a.normalized().dot(b.normalized()), -1.0, 1.0);
  return std::acos(c) / kDeg;
}

Mat3 vehicle_axes(const Vec3& up, const Vec3& forward) {
  const Vec3 down = -up.normalized();
  Vec3 fw = forward - forward.dot(down) * down;
  if (!(fw.norm() > 1e-9)) fw = std::abs(down.x()) < 0.9 ? Vec3::UnitX() : Vec3::UnitY();
  fw = (fw - fw.dot(down) * down).normalized();
  Mat3 C;
  C.row(0) = fw.transpose();
  C.row(1) = down.cross(fw).transpose();
  C.row(2) = down.transpose();
  return C;
}

namespace {

/// Mean specific force per `bin` seconds where every sample of the bin is filled, with
/// the index of the chunk it falls in.
struct Bins {
  std::vector<Vec3> f;
  std::vector<int> chunk;
};

Bins bin_series(const Series& s, double bin, double chunk) {
  Bins b;
  const std::size_t n = std::max<std::size_t>(1, static_cast<std::size_t>(std::lround(bin / s.dt)));
  for (std::size_t k = 0; k + n <= s.size(); k += n) {
    Vec3 sum = Vec3::Zero();
    bool all = true;
    for (std::size_t q = k; q < k + n; ++q) {
      all = all && s.filled[q];
      sum += s.accel[q];
    }
    if (!all) continue;
    b.f.push_back(sum / static_cast<double>(n));
    b.chunk.push_back(static_cast<int>(std::floor((s.time(k) - s.t0) / chunk)));
  }
  return b;
}

/// The demeaned (per chunk) vehicle-frame specific force of the bins; chunks shorter than
/// a fifth of the rest are left out (their mean is poorly known).
std::vector<Vec3> demeaned(const Bins& b, const Mat3& C, double bin, double chunk) {
  std::vector<Vec3> out;
  const int min_count = std::max(4, static_cast<int>(chunk / bin / 5.0));
  for (std::size_t i = 0; i < b.f.size();) {
    std::size_t j = i;
    Vec3 mean = Vec3::Zero();
    while (j < b.f.size() && b.chunk[j] == b.chunk[i]) mean += C * b.f[j++];
    const int count = static_cast<int>(j - i);
    if (count >= min_count) {
      mean /= static_cast<double>(count);
      for (std::size_t q = i; q < j; ++q) out.push_back(C * b.f[q] - mean);
    }
    i = j;
  }
  return out;
}

}  // namespace

LevelFit fit_level(const Series& s, const Vec3& up0, const Vec3& forward, const LevelFitOptions& o) {
  LevelFit fit;
  const Bins bins = bin_series(s, o.bin, o.chunk);
  Vec3 up = up0.normalized();
  for (int it = 0; it < o.iterations; ++it) {
    const Mat3 C = vehicle_axes(up, forward);
    const std::vector<Vec3> f = demeaned(bins, C, o.bin, o.chunk);
    fit.bins = static_cast<int>(f.size());
    if (fit.bins < o.min_bins) {
      fit.why = fmt("%.0f s of data in whole minutes (%.0f s needed)", fit.bins * o.bin,
                    o.min_bins * o.bin);
      return fit;
    }
    Eigen::Matrix2d A = Eigen::Matrix2d::Zero();
    Eigen::Vector2d r = Eigen::Vector2d::Zero();
    for (const Vec3& v : f) {
      A += v.head<2>() * v.head<2>().transpose();
      r += v.head<2>() * v.z();
    }
    fit.excitation = std::sqrt(A.trace() / static_cast<double>(fit.bins));
    if (fit.excitation < o.min_excitation || std::abs(A.determinant()) < 1e-12 * A.trace() * A.trace()) {
      fit.why = fmt("the vehicle hardly accelerated or turned (rms %.3f m/s^2)", fit.excitation);
      return fit;
    }
    const Eigen::Vector2d beta = A.ldlt().solve(r);
    double ss = 0.0;
    for (const Vec3& v : f) ss += std::pow(v.z() - beta.dot(v.head<2>()), 2);
    const Eigen::Matrix2d cov = ss / static_cast<double>(fit.bins - 2) * A.inverse();
    fit.sigma_pitch_deg = std::sqrt(cov(0, 0)) / kDeg;
    fit.sigma_roll_deg = std::sqrt(cov(1, 1)) / kDeg;
    // f_z = down . f: the down axis less the slopes along forward and right leaves the
    // vertical specific force uncorrelated with the horizontal.
    const Vec3 down = C.row(2).transpose() - beta.x() * C.row(0).transpose() - beta.y() * C.row(1).transpose();
    up = -down.normalized();
  }
  fit.up = up;
  fit.found = fit.sigma_roll_deg <= o.max_sigma_deg && fit.sigma_pitch_deg <= o.max_sigma_deg;
  if (!fit.found)
    fit.why = fmt("too uncertain (+- %.1f deg roll, +- %.1f deg pitch)", fit.sigma_roll_deg, fit.sigma_pitch_deg);
  return fit;
}

}  // namespace wheelins::survey
