// The chip error model of chip_errors.hpp: the per-sample error processes and the
// sensor-fault events on a chip's output.
#include "wheelins/sim/chip_errors.hpp"

#include <algorithm>
#include <cmath>

namespace wheelins::sim {

namespace {
double round_to(double x, double lsb) { return std::nearbyint(x / lsb) * lsb; }
}  // namespace

ChipErrors::ChipErrors(const SimConfig& cfg, const ChipModel& m)
    : e_(cfg.errors), m_(m),
      gm_g_(cfg.seed, m.name + "/gyro_gm"), gm_a_(cfg.seed, m.name + "/accel_gm"),
      arw_(cfg.seed, m.name + "/gyro_arw"), vrw_(cfg.seed, m.name + "/accel_vrw"),
      wheel_noise_(cfg.seed, m.name + "/wheel_noise"),
      bg_gm_(m.gyro_gm0), ba_gm_(m.accel_gm0),
      on_gm_g_(cfg.on("gyro_gm")), on_gm_a_(cfg.on("accel_gm")), on_arw_(cfg.on("arw")),
      on_vrw_(cfg.on("vrw")), on_sat_(cfg.on("saturation")), on_q_(cfg.on("quantization")) {
  const double dt = 1.0 / cfg.rate_hz;
  phi_g_ = std::exp(-dt / e_.gyro_gm_tau);
  q_g_ = e_.gyro_gm_sigma * std::sqrt(1.0 - phi_g_ * phi_g_);
  phi_a_ = std::exp(-dt / e_.accel_gm_tau);
  q_a_ = e_.accel_gm_sigma * std::sqrt(1.0 - phi_a_ * phi_a_);
  s_arw_ = e_.gyro_arw / std::sqrt(dt);
  s_vrw_ = e_.accel_vrw / std::sqrt(dt);
}

void ChipErrors::apply(double dT, const Vec3& w, const Vec3& f, Vec3& wm, Vec3& fm,
                       double wheel_sigma, const Vec3* gyro_step, const Vec3* accel_step) {
  if (on_gm_g_)
    for (int i = 0; i < 3; ++i) bg_gm_[i] = phi_g_ * bg_gm_[i] + q_g_ * gm_g_.normal();
  if (on_gm_a_)
    for (int i = 0; i < 3; ++i) ba_gm_[i] = phi_a_ * ba_gm_[i] + q_a_ * gm_a_.normal();
  bg_ = m_.gyro_bias + bg_gm_ + m_.gyro_tempco * dT;
  ba_ = m_.accel_bias + ba_gm_ + m_.accel_tempco * dT;
  if (gyro_step) bg_ += *gyro_step;
  if (accel_step) ba_ += *accel_step;
  wm = m_.gyro_T * w + bg_;
  fm = m_.accel_T * f + ba_;
  for (int i = 0; i < 3; ++i) {
    if (on_arw_) wm[i] += s_arw_ * arw_.normal();
    if (on_vrw_) fm[i] += s_vrw_ * vrw_.normal();
    if (wheel_sigma > 0.0) fm[i] += wheel_sigma * wheel_noise_.normal();
    if (on_sat_) {
      wm[i] = std::clamp(wm[i], -e_.gyro_range, e_.gyro_range);
      fm[i] = std::clamp(fm[i], -e_.accel_range, e_.accel_range);
    }
    if (on_q_) {
      wm[i] = round_to(wm[i], e_.gyro_lsb);
      fm[i] = round_to(fm[i], e_.accel_lsb);
    }
  }
}

ChipFaults::ChipFaults(const std::vector<FaultEvent>& faults, const std::string& group,
                       const std::string& chip) {
  for (const FaultEvent& f : faults) {
    if (!f.targets(group, chip)) continue;
    if (f.kind == FaultKind::kDropout) dropouts_.push_back(&f);
    if (f.kind == FaultKind::kGyroBiasJump || f.kind == FaultKind::kAccelBiasJump) jumps_.push_back(&f);
    if (f.kind == FaultKind::kStuck) stuck_.push_back({&f, 0.0, false});
  }
}

bool ChipFaults::steps(double tau, Vec3& gyro, Vec3& accel) const {
  bool any = false;
  gyro.setZero();
  accel.setZero();
  for (const FaultEvent* f : jumps_)
    if (f->active(tau)) {
      (f->gyro ? gyro : accel)[f->axis] += f->value_si();
      any = true;
    }
  return any;
}

void ChipFaults::hold(double tau, Vec3& wm, Vec3& fm) {
  for (Stuck& s : stuck_) {
    double& x = (s.f->gyro ? wm : fm)[s.f->axis];
    if (s.f->active(tau)) {
      if (!s.have) s.value = x, s.have = true;
      x = s.value;
    } else if (tau < s.f->start) {
      s.value = x;
      s.have = true;
    }
  }
}

bool ChipFaults::dropped(double tau) const {
  for (const FaultEvent* f : dropouts_)
    if (f->active(tau)) return true;
  return false;
}

}  // namespace wheelins::sim
