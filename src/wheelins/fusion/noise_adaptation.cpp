// The noise model learned from the data (noise_adaptation.hpp).
#include "wheelins/fusion/noise_adaptation.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace wheelins {

NoiseAdaptation::NoiseAdaptation(const NoiseAdaptationOptions& opt, Subsystems& subs,
                                 double update_interval)
    : opt_(opt), subs_(subs), dt_(update_interval), st_(static_cast<std::size_t>(subs.size())) {
  opt_.validate();
}

void NoiseAdaptation::on_start(int i, const StaticAccumulator& stat, double t0) {
  Subsystem& s = subs_[i];
  State& st = st_[i];
  st.given = s.module().noise;
  st.r_given = s.is_wheel() ? subs_.wheel(i).velocity_noise().diagonal()
                            : subs_.body().velocity_noise().diagonal();
  st.gyro_rest = estimate_sensor_noise(stat.gyro_allan());
  st.accel_rest = estimate_sensor_noise(stat.accel_allan());
  st.t_start = t0;
  st.starts = s.ekf().starts();
  st.errors_start = s.ekf().errors();
  double vrw_floor = 0.0;
  ImuNoise q = s.process_noise();
  if (opt_.enabled && st.gyro_rest.valid) {
    // At rest the gyro shows its white noise (with its quantization): the angle random walk
    // from here on, whatever the manifest said; and the alignment's bias estimate is as
    // good as that noise over the period, far better than a datasheet's turn-on figure.
    q.gyro_arw = st.gyro_rest.white;
    st.bias_start_sigma = st.gyro_rest.white / std::sqrt(std::max(st.gyro_rest.duration, 1e-3));
    s.ekf().set_gyro_bias_uncertainty(st.bias_start_sigma);
  } else {
    st.bias_start_sigma = s.process_noise().gyro_bias_std;
  }
  if (opt_.enabled && st.accel_rest.valid) vrw_floor = st.accel_rest.white;
  q.acc_vrw = std::max(q.acc_vrw, vrw_floor);
  s.set_process_noise(q);
  st.vrw_start = q.acc_vrw;
  VelocityNoiseMatcher::Options mo;
  mo.window = opt_.window;
  mo.r_floor_fraction = opt_.r_floor_fraction;
  mo.vrw_max = std::max(opt_.vrw_max, q.acc_vrw);
  st.matcher.reset(mo, q.acc_vrw, vrw_floor, st.r_given);
  st.bias.reset(opt_.window, q.gyro_bias_std, std::min(opt_.bias_floor, q.gyro_bias_std),
                q.gyro_bias_tau);
  st.matcher_ready = true;
}

void NoiseAdaptation::check_restart(int i, double t) {
  State& st = st_[i];
  const int starts = subs_[i].ekf().starts();
  if (starts == st.starts) return;
  // A restart (outage, isolation): the module keeps the figures identified so far
  // (Subsystem::process_noise), the innovation sequence starts again after settling.
  st.starts = starts;
  st.t_start = t;
  st.matcher.break_sequence();
  st.errors_start = subs_[i].ekf().errors();
}

void NoiseAdaptation::prepare_velocity(int i, Measurement& m) {
  State& st = st_[i];
  if (!opt_.enabled || !st.matcher_ready || !st.matcher.adapted()) return;
  // The identified noise in place of the given one; what the measurement builder added on
  // top (a mean speed's point offset in a turn) stays, and a row without a speed keeps its
  // large variance.
  const Vec3 dr = st.matcher.r_diag() - st.r_given;
  for (int k = 0; k < 3; ++k)
    if (!(k == 0 && m.R(0, 0) >= kNoSpeedVar)) m.R(k, k) += dr(k);
}

void NoiseAdaptation::after_velocity(int i, const Measurement& m, const UpdateReport& rep,
                                     const Vec3& bias_before, double t) {
  State& st = st_[i];
  check_restart(i, t);
  ++st.velocity.updates;
  if (!rep.accepted) ++st.velocity.rejected;
  if (rep.test_ratio > 1.0) ++st.velocity.over;
  st.velocity.sum_nis += rep.nis;
  if (!st.matcher_ready) return;
  Subsystem& s = subs_[i];
  const bool speed_row = m.R(0, 0) < kNoSpeedVar;
  const bool moving = s.reference_velocity_inW().norm() > opt_.min_speed;
  if (rep.accepted && speed_row && moving && t >= st.t_start + opt_.settle) {
    Vec3 dz, S;
    for (int k = 0; k < 3; ++k) {
      dz(k) = rep.innovation[k];
      S(k) = rep.innovation_var[k];
    }
    st.matcher.add(dz, S, dt_);
    if (opt_.enabled && st.matcher.adapted()) {
      ImuNoise q = s.process_noise();
      q.acc_vrw = st.matcher.vrw();
      if (s.is_wheel()) {
        // A Wheel-IMU's gyro biases are seen by its own velocity updates (the axle's through
        // the speed, the others through the wheel's attitude): their instability follows the
        // corrections. A Body-IMU's yaw-axis bias is corrected through the position
        // constraint, which its velocity updates do not see: it keeps its prior.
        st.bias.add(s.ekf().errors().bg - bias_before, dt_);
        q.gyro_bias_std = st.bias.sigma();
      }
      s.set_process_noise(q);
    }
  } else {
    st.matcher.break_sequence();
  }
  check_excursions(i, t);
}

void NoiseAdaptation::after_position(int i, const UpdateReport& rep) {
  State& st = st_[i];
  ++st.position.updates;
  if (!rep.accepted) ++st.position.rejected;
  if (rep.test_ratio > 1.0) ++st.position.over;
  st.position.sum_nis += rep.nis;
}

void NoiseAdaptation::check_excursions(int i, double t) {
  // An estimate beyond 3 sigma of its prior is a value no chip of the stated quality has:
  // the data push it there through something the model lacks (a lever arm, a radius...).
  State& st = st_[i];
  const StrapdownEkf& ekf = subs_[i].ekf();
  const ProcessNoise& q = subs_[i].process_noise();
  const ImuErrors& e = ekf.errors();
  struct Group {
    int base;
    const Vec3* now;
    const Vec3* start;
    double sigma;
  };
  const Vec3 zero = Vec3::Zero();
  const Group groups[] = {{BG, &e.bg, &st.errors_start.bg, st.given.gyro_bias_std},
                          {BA, &e.ba, &zero, st.given.acc_bias_std},
                          {SG, &e.sg, &zero, st.given.gyro_sf_std},
                          {SA, &e.sa, &zero, st.given.acc_sf_std}};
  for (const Group& g : groups)
    for (int a = 0; a < 3; ++a) {
      const int k = g.base + a;
      if (q.held(k) || st.excursion_seen[k]) continue;
      const double v = (*g.now)(a) - (*g.start)(a);
      if (std::abs(v) > 3.0 * g.sigma) {
        st.excursion_seen[k] = true;
        st.excursions.push_back({k, t, v, g.sigma});
      }
    }
}


ModuleNoiseReport NoiseAdaptation::report(int i) const {
  const State& st = st_[i];
  const Subsystem& s = subs_[i];
  ModuleNoiseReport r;
  r.module = s.module().name;
  r.wheel = s.is_wheel();
  r.given = st.given;
  r.gyro_rest = st.gyro_rest;
  r.accel_rest = st.accel_rest;
  r.vrw_start = st.vrw_start;
  r.vrw = s.process_noise().acc_vrw;
  r.arw = s.process_noise().gyro_arw;
  r.gyro_bias_instability = s.process_noise().gyro_bias_std;
  r.gyro_bias_start_sigma = st.bias_start_sigma;
  r.adapted = opt_.enabled && st.matcher.adapted();
  r.velocity_std_given = st.r_given.cwiseSqrt();
  r.velocity_std = r.adapted ? Vec3(st.matcher.r_diag().cwiseSqrt()) : r.velocity_std_given;
  r.nis_axes = st.matcher.nis_axes();
  r.velocity = st.velocity;
  r.position = st.position;
  for (int k = 0; k < kStateDim; ++k) {
    if (s.process_noise().held(k)) r.held.push_back(k);
    else if (s.process_noise().velocity_gain(k) == 0.0) r.constraint_only.push_back(k);
  }
  r.excursions = st.excursions;
  // Where the noise model and the data disagree, and what to change.
  char w[400];
  const double nis = st.velocity.mean_nis();
  if (st.velocity.updates >= 20 && nis > 2.0 * st.velocity.dim) {
    std::snprintf(w, sizeof w,
                  "%s velocity updates: mean NIS %.1f (%d if consistent): the innovations are %.1f x "
                  "what the noise model predicts; %s",
                  r.module.c_str(), nis, st.velocity.dim, std::sqrt(nis / st.velocity.dim),
                  opt_.enabled ? "even the identified noise is too small: check the geometry "
                                 "(lever_arm_b_m, mounting_deg, wheel_radius_m) and time_offset_s"
                               : "raise acc_vrw_m_s_sqrt_h (the noise of the constraint axes) or "
                                 "the velocity sigma (filter.wheel_velocity_std_m_s), or let the "
                                 "noise adapt");
    r.warnings.push_back(w);
  } else if (!opt_.enabled && st.velocity.updates >= 20 && nis < 0.25 * st.velocity.dim) {
    std::snprintf(w, sizeof w,
                  "%s velocity updates: mean NIS %.2f (%d if consistent): the noise model is %.1f x "
                  "too pessimistic; lower acc_vrw_m_s_sqrt_h or the velocity sigma",
                  r.module.c_str(), nis, st.velocity.dim, std::sqrt(st.velocity.dim / std::max(nis, 1e-9)));
    r.warnings.push_back(w);
  }
  if (r.adapted && r.vrw >= opt_.vrw_max * (1 - 1e-9)) {
    std::snprintf(w, sizeof w,
                  "%s: the velocity random walk reached its ceiling %.1f m/s/sqrt(h): the velocity "
                  "innovations are not noise the model can hold",
                  r.module.c_str(), opt_.vrw_max * 60.0);
    r.warnings.push_back(w);
  }
  for (const PriorExcursion& x : st.excursions) {
    const bool gyro_bias = x.state >= BG && x.state < BG + 3;
    const bool accel_bias = x.state >= BA && x.state < BA + 3;
    const double unit = gyro_bias ? 3600.0 / kDeg : (accel_bias ? 1.0 : 1e6);
    const char* u = gyro_bias ? "deg/h" : (accel_bias ? "m/s^2" : "ppm");
    std::snprintf(w, sizeof w,
                  "%s: estimate %s at %.1f s is %.4g %s, beyond 3 sigma of its prior %.4g %s%s",
                  r.module.c_str(), error_state_name(x.state), x.t, x.value * unit, u,
                  x.prior_sigma * unit, u,
                  (accel_bias && r.wheel && x.state != BA)
                      ? " (a Wheel-IMU's accelerometer bias in the wheel plane looks like the "
                        "centripetal acceleration of a lever-arm error: check lever_arm_b_m)"
                      : "");
    r.warnings.push_back(w);
  }
  return r;
}

}  // namespace wheelins
