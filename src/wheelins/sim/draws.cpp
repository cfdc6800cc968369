// Every random draw of a dataset (draws.hpp): the modules' physical parameters and the
// chips' error parameters, each from its own named stream.
#include "wheelins/sim/draws.hpp"

namespace wheelins::sim {

ModuleModel draw_module(const SimConfig& cfg, const std::string& drawn_as, const ModuleGeometry& geo,
                        double cruise) {
  const ErrorParams& e = cfg.errors;
  ModuleModel m;
  m.truth = geo;
  m.manifest = geo;
  const bool wheel = m.truth.wheel;
  m.radius = m.radius_manifest = wheel ? cfg.vehicle.wheel_radius : 0.0;
  {
    Rng r(cfg.seed, drawn_as + "/radius");
    const double d = r.normal(e.radius_rel);
    if (wheel && cfg.on("radius")) m.radius = cfg.vehicle.wheel_radius * (1.0 + d);
  }
  if (wheel && cfg.on("slip")) m.slip_coeff = e.slip_coeff;
  {
    Rng r(cfg.seed, drawn_as + "/time_offset");
    const double d = r.normal(e.time_offset);
    if (cfg.on("time_offset")) m.time_offset = d;
  }
  {
    Rng r(cfg.seed, drawn_as + "/temperature");
    const double d = e.temp_rise * (1.0 + 0.2 * r.normal());
    if (cfg.on("temperature")) m.temp_rise = d;
  }
  {
    Rng r(cfg.seed, drawn_as + "/vibration");
    Vibration v = wheel ? Vibration::draw(r, e.vib_wheel_accel, e.vib_wheel_rate, e.vib_wheel_band)
                        : Vibration::draw(r, e.vib_body_accel, e.vib_body_rate, e.vib_body_band);
    if (cfg.on("vibration")) m.vibration = std::move(v);
    m.vib_cruise_speed = cruise;
  }
  {
    Rng r(cfg.seed, drawn_as + "/calibration");
    Vec3 dl, dm, dp;
    for (int i = 0; i < 3; ++i) dl[i] = r.normal(e.cal_lever_arm);
    for (int i = 0; i < 3; ++i) dm[i] = r.normal(e.cal_mounting);
    for (int i = 0; i < 3; ++i) dp[i] = r.normal(e.cal_position);
    const double dr = r.normal(e.cal_radius_rel);
    if (cfg.on("calibration")) {
      if (wheel) m.manifest.lever_arm_inB += dl;
      m.manifest.mounting_rpy += dm;
      m.manifest.p_inV += dp;
      if (wheel) m.radius_manifest *= 1.0 + dr;
    }
  }
  return m;
}

ChipModel draw_chip(const SimConfig& cfg, const std::string& name, const std::string& drawn_as) {
  const ErrorParams& e = cfg.errors;
  ChipModel ch;
  ch.name = name;
  const std::string streams = drawn_as.empty() ? name : drawn_as;
  auto draw3 = [&](const std::string& stream, double sigma) {
    Rng r(cfg.seed, streams + "/" + stream);
    // The draws in a fixed order (z, y, x: the order the simulator's data were first made
    // in), not as a constructor's arguments, whose order of evaluation the compiler chooses.
    const double z = r.normal(sigma), y = r.normal(sigma), x = r.normal(sigma);
    return Vec3(x, y, z);
  };
  auto draw_T = [&](const std::string& stream, double sf, double mis, bool sf_on, bool mis_on) {
    Rng r(cfg.seed, streams + "/" + stream);
    Mat3 T = Mat3::Identity();
    for (int i = 0; i < 3; ++i) {
      const double s = r.normal(sf);
      if (sf_on) T(i, i) += s;
    }
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) {
        if (i == j) continue;
        const double m2 = r.normal(mis);
        if (mis_on) T(i, j) = m2;
      }
    return T;
  };
  const Vec3 z = Vec3::Zero();
  ch.gyro_bias = cfg.on("gyro_bias") ? draw3("gyro_bias", e.gyro_bias) : z;
  ch.accel_bias = cfg.on("accel_bias") ? draw3("accel_bias", e.accel_bias) : z;
  ch.gyro_gm0 = cfg.on("gyro_gm") ? draw3("gyro_gm0", e.gyro_gm_sigma) : z;
  ch.accel_gm0 = cfg.on("accel_gm") ? draw3("accel_gm0", e.accel_gm_sigma) : z;
  ch.gyro_T = draw_T("gyro_T", e.gyro_sf, e.gyro_misalign, cfg.on("scale_factor"), cfg.on("misalignment"));
  ch.accel_T = draw_T("accel_T", e.accel_sf, e.accel_misalign, cfg.on("scale_factor"), cfg.on("misalignment"));
  ch.gyro_tempco = cfg.on("temperature") ? draw3("gyro_tempco", e.gyro_tempco) : z;
  ch.accel_tempco = cfg.on("temperature") ? draw3("accel_tempco", e.accel_tempco) : z;
  return ch;
}

}  // namespace wheelins::sim
