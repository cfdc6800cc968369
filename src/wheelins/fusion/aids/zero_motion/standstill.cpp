// The standstill detector of standstill.hpp.
#include "wheelins/fusion/aids/zero_motion/standstill.hpp"

#include <algorithm>

namespace wheelins {

void StandstillDetector::add(int i, const ImuSample& b, const ImuErrors& errors) {
  if (!opt_.enabled) return;
  Window& w = w_[i];
  w.block_dtheta += b.dtheta;
  w.block_dvel += b.dvel;
  w.block_t += b.dt;
  w.sum_dtheta += b.dtheta;
  w.sum_t += b.dt;
  if (w.block_t + 1e-9 < opt_.block) return;
  // A whole block: its mean rate with the estimates removed, its mean specific force.
  ImuSample block;
  block.dt = w.block_t;
  block.dtheta = w.block_dtheta;
  block.dvel = w.block_dvel;
  const ImuSample c = compensate(block, errors);
  w.max_rate = std::max(w.max_rate, c.dtheta.norm() / w.block_t);
  const Vec3 f = w.block_dvel / w.block_t;
  w.f_min = w.f_min.cwiseMin(f);
  w.f_max = w.f_max.cwiseMax(f);
  ++w.blocks;
  w.block_dtheta.setZero();
  w.block_dvel.setZero();
  w.block_t = 0.0;
}

bool StandstillDetector::evaluate(const std::array<bool, kMaxModules>& vehicle, int n, double t) {
  if (!opt_.enabled) return false;
  bool all_quiet = true, any = false;
  for (int i = 0; i < n; ++i) {
    Window& w = w_[i];
    Result& r = last_[i];
    // At least two whole blocks: a window of data, not a few samples after a gap.
    r.quiet = w.blocks >= 2 && w.max_rate < opt_.max_rate &&
              (w.f_max - w.f_min).maxCoeff() <= opt_.max_force_spread;
    r.duration = w.sum_t;
    r.mean_raw_rate = w.sum_t > 0.0 ? Vec3(w.sum_dtheta / w.sum_t) : Vec3::Zero();
    if (vehicle[i]) {
      any = true;
      all_quiet = all_quiet && r.quiet;
    }
    w = Window();
  }
  const bool still = any && all_quiet;
  if (!still) still_since_ = -1e300;
  else if (still_since_ == -1e300) still_since_ = last_t_ == -1e300 ? t : last_t_;
  last_t_ = t;
  standing_ = still && t - still_since_ + 1e-9 >= opt_.min_time;
  return standing_;
}

}  // namespace wheelins
