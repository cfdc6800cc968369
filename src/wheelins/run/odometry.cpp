// Wheel odometry with a gyro heading: the naive baseline (odometry.hpp).
#include "wheelins/run/odometry.hpp"

#include <cmath>
#include <memory>

#include "wheelins/io/imu_file.hpp"
#include "wheelins/io/text_util.hpp"

namespace wheelins {

OdometryResult run_wheel_odometry(const OdometryRequest& r) {
  const Manifest& m = r.manifest;
  const std::string man = io_detail::quote(m.path);
  if (r.wheels.empty()) throw InputError("odometry: no wheel module given");
  std::vector<const ModuleSpec*> specs;
  for (const auto& name : r.wheels) {
    const ModuleSpec* s = m.find(name);
    if (!s) throw InputError(man + ": no module named '" + name + "'");
    if (s->kind != ModuleKind::kWheel) throw InputError(man + ": module '" + name + "' is not a wheel IMU");
    specs.push_back(s);
  }
  const ModuleSpec* gyro = nullptr;
  if (!r.gyro.empty()) {
    gyro = m.find(r.gyro);
    if (!gyro) throw InputError(man + ": no module named '" + r.gyro + "'");
    if (gyro->kind != ModuleKind::kBody) throw InputError(man + ": module '" + r.gyro + "' is not a body IMU");
  } else if (specs.size() < 2 || std::abs(specs[0]->p_inV.y() - specs[1]->p_inV.y()) < 0.05) {
    throw InputError("odometry: a heading needs a body IMU (the gyro) or two wheels on opposite sides");
  }
  std::vector<std::unique_ptr<ImuStream>> streams;
  std::vector<const ModuleSpec*> all = specs;
  if (gyro) all.push_back(gyro);
  for (const ModuleSpec* s : all)
    streams.push_back(std::make_unique<ImuFileReader>(m.resolve(s->file), imu_read_options(*s)));
  ImuMerger merger(std::move(streams));

  const std::size_t nw = specs.size();
  std::vector<Mat3> C(all.size());
  for (std::size_t i = 0; i < all.size(); ++i)
    C[i] = all[i]->kind == ModuleKind::kWheel ? wheel_sensor_to_body(*all[i]) : dcm_from_euler(all[i]->mounting_rpy);
  std::vector<Vec3> bias_sum(all.size(), Vec3::Zero()), rate(all.size(), Vec3::Zero());
  std::vector<double> bias_n(all.size(), 0.0);
  std::vector<bool> seen(all.size(), false);
  const earth::LocalFrame frame(m.origin);
  OdometryResult out;
  out.heading_source = gyro ? "the gyro of " + gyro->name : "the speed difference of " + specs[0]->name + " and " + specs[1]->name;
  double psi = m.initial_heading, t_prev = 0.0, next_out = -1e300;
  Vec3 p = Vec3::Zero();
  bool started = false;
  auto body_rate = [&](std::size_t i) {
    const Vec3 b = bias_n[i] > 0.0 ? Vec3(bias_sum[i] / bias_n[i]) : Vec3::Zero();
    return Vec3(C[i] * (rate[i] - b));
  };
  // One step to the first wheel's sample at t, with every module's latest sample up to t.
  auto step = [&](double t) {
    bool all_seen = true;
    for (bool x : seen) all_seen = all_seen && x;
    if (!all_seen) return;
    // Speeds of the wheels, the yaw rate (counter-clockwise from above), the speed at o.
    std::vector<double> v(nw);
    for (std::size_t i = 0; i < nw; ++i)
      v[i] = -specs[i]->axle_sign * (specs[i]->odometry_radius > 0.0 ? specs[i]->odometry_radius : specs[i]->wheel_radius) *
             body_rate(i).x();
    const double yaw_up = gyro ? -body_rate(nw).z() : (v[1] - v[0]) / (specs[1]->p_inV.y() - specs[0]->p_inV.y());
    double vo = 0.0;
    for (std::size_t i = 0; i < nw; ++i) vo += v[i] - yaw_up * specs[i]->p_inV.y();
    vo /= static_cast<double>(nw);
    if (!started) {
      started = true;
      t_prev = t;
      out.t_start = t;
    }
    const double dt = t - t_prev;
    t_prev = t;
    const double psi_mid = psi - 0.5 * yaw_up * dt;
    p += Vec3(std::cos(psi_mid), std::sin(psi_mid), 0.0) * vo * dt;
    psi = wrap_pi(psi - yaw_up * dt);
    out.distance += std::abs(vo) * dt;
    out.t_end = t;
    if (t + 1e-9 < next_out) return;
    next_out = t + r.output_interval;
    TrajectoryRecord rec;
    rec.t = t;
    rec.p_inN = p;
    rec.lla = frame.geodetic_from_ned(p);
    rec.v_inN = Vec3(std::cos(psi), std::sin(psi), 0.0) * vo;
    rec.rpy = Vec3(0.0, 0.0, psi);
    rec.p_std = rec.v_std = rec.rpy_std = Vec3::Constant(std::nan(""));
    ++out.records;
    if (r.on_record) r.on_record(rec);
  };
  // The first wheel's samples drive the integration; a step is taken once the merged
  // samples have passed its time (the other modules' samples of the same time come after
  // it: the merger gives equal times in module order).
  bool pending = false;
  double pending_t = 0.0;
  std::size_t k = 0;
  ImuSample s;
  while (merger.next(k, s)) {
    if (pending && s.t > pending_t) {
      step(pending_t);
      pending = false;
    }
    rate[k] = s.dtheta / s.dt;
    seen[k] = true;
    if (s.t <= m.static_end) {
      if (s.t >= m.static_start) bias_sum[k] += rate[k], bias_n[k] += 1.0;
      continue;
    }
    if (k == 0) {
      pending = true;
      pending_t = s.t;
    }
  }
  if (pending) step(pending_t);
  if (!started)
    throw InputError(man + ": the data end before the static period does: nothing to dead-reckon");
  return out;
}

}  // namespace wheelins
