#include "wheelins/fusion/navigator.hpp"

#include <chrono>
#include <cmath>
#include <numeric>
#include <sstream>

namespace wheelins {

std::string NavigatorOptions::describe() const {
  std::ostringstream o;
  auto onoff = [](bool b) { return b ? "on" : "off"; };
  o << "velocity update interval:   " << wheel.velocity_update_interval << " s\n"
    << "wheel speed window:         " << wheel.speed_window << " s\n"
    << "wheel speed sharing:        "
    << (fusion.speed == SpeedSharing::kMean ? "mean of Wheel-IMUs (paper)" : "own wheel") << "\n"
    << "Wheel-INS velocity sigma:   " << wheel.velocity_std.transpose() << " m/s\n"
    << "Body-INS velocity sigma:    " << body.velocity_std.transpose() << " m/s\n"
    << "position constraint:        " << onoff(fusion.position_constraint) << ", every "
    << fusion.position_update_interval << " s, sigma " << fusion.position_std << " m\n"
    << "Body-INS level to wheels:   " << onoff(fusion.share_level) << "\n"
    << "filter structure:           "
    << (fusion.centralized ? "centralized (one joint covariance)" : "distributed (paper)") << "\n"
    << "innovation gates (vel/pos): " << wheel.gate << " / " << fusion.position_gate
    << " (0 = off)\n"
    << "initial sigma:              position " << wheel.init.position << " m, velocity "
    << wheel.init.velocity << " m/s, roll/pitch " << wheel.init.roll_pitch / kDeg
    << " deg, heading " << wheel.init.heading / kDeg << " deg\n"
    << "mechanization:              "
    << (mechanization == MechanizationOptions::Method::kRotationExact ? "rotation-exact"
                                                                       : "classic two-sample")
    << "\n"
    << "earth rotation:             " << (earth_rotation ? "compensated" : "ignored") << "\n"
    << "output interval:            "
    << (output_interval > 0 ? std::to_string(output_interval) + " s" : std::string("every epoch"))
    << "\n";
  return o.str();
}

Navigator::Navigator(const Manifest& manifest, const std::vector<std::string>& modules,
                     const NavigatorOptions& options, Sink sink)
    : manifest_(manifest), opt_(options), sink_(std::move(sink)), frame_(manifest.origin) {
  if (modules.empty()) throw InputError("no module selected: name at least one Wheel-IMU");
  MechanizationOptions mech;
  mech.method = opt_.mechanization;
  mech.gravity = manifest_.gravity_or_default();
  if (opt_.earth_rotation) mech.omega_ie_inW = earth::earth_rate_ned(manifest_.origin.lat);
  for (const auto& name : modules) {
    const ModuleSpec* m = manifest_.find(name);
    if (!m) {
      std::string known;
      for (const auto& mm : manifest_.modules) known += (known.empty() ? "" : ", ") + mm.name;
      throw InputError("'" + manifest_.path.string() + "': no module named '" + name +
                       "' (modules: " + known + ")");
    }
    if (m->kind == ModuleKind::kWheel) {
      auto w = std::make_unique<WheelIns>(*m, opt_.wheel, mech);
      wheels_.push_back(w.get());
      subs_.push_back(std::move(w));
    } else {
      if (body_)
        throw InputError("module '" + name + "': only one Body-IMU can share its attitude; '" +
                         body_->module().name + "' is already selected");
      auto b = std::make_unique<BodyIns>(*m, opt_.body, mech);
      body_ = b.get();
      body_index_ = static_cast<int>(subs_.size());
      subs_.push_back(std::move(b));
    }
  }
  if (wheels_.empty())
    throw InputError("no Wheel-IMU among the selected modules: at least one IMU must be on a "
                     "wheel to measure the wheel speed");
  weights_ = opt_.fusion.weights;
  if (weights_.empty()) weights_.assign(subs_.size(), 1.0);
  if (weights_.size() != subs_.size())
    throw InputError("fusion weights: " + std::to_string(weights_.size()) + " given for " +
                     std::to_string(subs_.size()) + " modules");
  const double wsum = std::accumulate(weights_.begin(), weights_.end(), 0.0);
  for (double w : weights_)
    if (!(w >= 0.0) || !(wsum > 0.0))
      throw InputError("fusion weights must be >= 0 with a positive sum");
  for (double& w : weights_) w /= wsum;
  static_.resize(subs_.size());
  rp_models_.resize(subs_.size());
}

Navigator::~Navigator() = default;

double Navigator::min_time() const {
  double t = subs_[0]->time();
  for (const auto& s : subs_) t = std::min(t, s->time());
  return t;
}

void Navigator::process(int index, const ImuSample& raw) {
  ++stats_.samples;
  Subsystem& s = *subs_[index];
  const ImuSample b = s.to_body(raw);
  if (!navigating_) {
    if (raw.t <= manifest_.static_start) return;
    if (raw.t <= manifest_.static_end + 1e-9) {
      static_[index].add(b);
      return;
    }
    start_navigation(manifest_.static_end);
  }
  s.propagate(b);
  if (joint_) joint_->propagate(index, s.ekf().last_dynamics(), s.ekf().noise(), b.dt);

  // Updates when every subsystem has reached the scheduled time.
  const double t_all = min_time();
  using Clock = std::chrono::steady_clock;
  if (t_all + 1e-9 >= next_velocity_t_) {
    const auto t0 = Clock::now();
    velocity_updates();
    stats_.velocity_step_seconds += std::chrono::duration<double>(Clock::now() - t0).count();
    ++stats_.velocity_steps;
    while (next_velocity_t_ <= t_all + 1e-9) next_velocity_t_ += opt_.wheel.velocity_update_interval;
  }
  if (subs_.size() > 1 && opt_.fusion.position_constraint && t_all + 1e-9 >= next_position_t_) {
    const auto t0 = Clock::now();
    position_update();
    stats_.position_step_seconds += std::chrono::duration<double>(Clock::now() - t0).count();
    ++stats_.position_steps;
    while (next_position_t_ <= t_all + 1e-9)
      next_position_t_ += opt_.fusion.position_update_interval;
  }

  if (index != 0) return;
  ++stats_.epochs;
  stats_.t_end = raw.t;
  if (raw.t + 1e-9 >= next_output_t_) {
    sink_(0, vehicle_record());
    if (subs_.size() > 1)
      for (int i = 0; i < subsystem_count(); ++i) sink_(i + 1, subsystem_record(i));
    ++stats_.records;
    if (opt_.output_interval > 0)
      while (next_output_t_ <= raw.t + 1e-9) next_output_t_ += opt_.output_interval;
  }
}

void Navigator::start_navigation(double t0) {
  for (std::size_t i = 0; i < subs_.size(); ++i) {
    if (static_[i].count() < 10)
      throw InputError("module '" + subs_[i]->module().name + "': only " +
                       std::to_string(static_[i].count()) + " samples in the static period [" +
                       std::to_string(manifest_.static_start) + ", " +
                       std::to_string(manifest_.static_end) +
                       "] s: the alignment needs a static period covered by the data");
    subs_[i]->start(static_[i], manifest_.initial_heading, t0);
  }
  if (opt_.fusion.centralized && subs_.size() > 1) {
    joint_ = make_joint_covariance(subsystem_count());
    for (int i = 0; i < subsystem_count(); ++i) {
      joint_->set_block(i, subs_[i]->ekf().covariance());
      subs_[i]->ekf().set_external_covariance(true);
    }
  }
  navigating_ = true;
  stats_.t_start = t0;
  next_output_t_ = t0;
  next_velocity_t_ = t0 + opt_.wheel.velocity_update_interval;
  next_position_t_ = t0 + opt_.fusion.position_update_interval;
}

void Navigator::share_level() {
  if (body_ && opt_.fusion.share_level) {
    const Vec3 rpy = body_->vehicle_rpy();
    for (WheelIns* w : wheels_) w->set_vehicle_level(rpy.x(), rpy.y());
  }
}

void Navigator::add_level_block(const Eigen::Matrix<double, 3, 2>& H_level, double c,
                                std::array<H3, kMaxCentralized>& h) const {
  if (!body_ || !opt_.fusion.share_level || c == 0.0) return;
  h[body_index_].block<3, 3>(0, PHI) +=
      c * H_level * vehicle_level_sensitivity(body_->C_VtoW());
}

void Navigator::velocity_measurement(int i, JointMeasurement& jm) const {
  // The same measurements as the distributed filter (eq. 5 for a Wheel-INS, eq. 6 for the
  // Body-INS), but one EKF over all error states (Section VI-B-2), so every dependence on
  // another IMU's state is in H instead of being ignored:
  //  - the mean wheel speed (1/n) sum_j (-a_j r_j omega_x,j) carries each Wheel-IMU's
  //    r delta omega_x of eq. (3): -(1/n) dspeed_j/d(b_g,x, s_g,x) in block j (dz = z_hat -
  //    z_meas); the Body-INS always uses the mean;
  //  - a Wheel-INS model uses the Body-INS roll/pitch (eq. 5, theta_3 and phi_3): its
  //    H_level times d(roll, pitch)/d(phi_3) in the Body-INS block.
  // Everything is evaluated at the current state: the speeds from the current gyro-x
  // estimates, the level from the current Body-INS attitude.
  const int N = subsystem_count();
  const double n = static_cast<double>(wheels_.size());
  double mean_speed = 0.0;
  Vec3 mean_point = Vec3::Zero();
  for (const WheelIns* w : wheels_) {
    mean_speed += w->wheel_speed() / n;
    mean_point += w->module().p_inV / n;
  }
  for (int j = 0; j < kMaxCentralized; ++j) jm.H[j].setZero();
  const bool wheel = subs_[i]->is_wheel();
  const bool mean = !wheel || (opt_.fusion.speed == SpeedSharing::kMean && n > 1);
  if (wheel) {
    const auto& w = static_cast<const WheelIns&>(*subs_[i]);
    WheelVelocityInput in = w.own_velocity_input();
    if (body_ && opt_.fusion.share_level) {
      const Vec3 rpy = body_->vehicle_rpy();
      in.vehicle_roll = rpy.x();
      in.vehicle_pitch = rpy.y();
    }
    if (mean) {  // the speed's sensitivities are added below, for every wheel
      in.measured_speed = mean_speed;
      in.dspeed_dbgx = in.dspeed_dsgx = 0.0;
    }
    const WheelVelocityModel m = wheel_velocity_model(in);
    jm.H[i] = m.H;
    add_level_block(m.H_level, 1.0, jm.H);
    jm.dz = m.innovation();
    jm.R = w.velocity_noise();
    if (mean) {
      // The mean of the wheel speeds is the speed of the mean of the wheel centres (o for a
      // left/right pair), not of this wheel's centre, which eq. (5) predicts: in a turn it is
      // off by yaw rate x (offset of this wheel from that point), +-omega_z track / 2, up to
      // five times the forward sigma. The distributed filter ignores it; the joint filter
      // must not, or its position constraint turns the opposite left/right speed errors
      // into a common heading error of every IMU (0.67 deg heading RMSE on error-free data).
      // Counted as forward noise at the Wheel-IMU's current yaw rate (its rate without the
      // spin about its axle c1 = C e_x), so H stays eq. (5)'s.
      const Mat3 C = w.ekf().state().C_ItoW();
      const Vec3 wv = C * w.ekf().omega_ib_b();
      const double yaw_rate = (wv - wv.dot(C.col(0)) * C.col(0)).z();  // without the spin
      const double e = yaw_rate * (mean_point - w.module().p_inV).norm();
      jm.R(0, 0) += e * e;
    }
    jm.gate = w.velocity_gate();
  } else {
    const BodyVelocityModel m = body_->velocity_model(mean_speed, mean_point);
    jm.H[i] = m.H;
    jm.dz = m.innovation();
    jm.R = body_->velocity_noise();
    jm.gate = body_->velocity_gate();
  }
  if (mean)
    for (int j = 0; j < N; ++j) {
      if (!subs_[j]->is_wheel()) continue;
      const WheelIns::SpeedSensitivity ds =
          static_cast<const WheelIns&>(*subs_[j]).speed_sensitivity();
      jm.H[j](0, BG) -= ds.dbgx / n;
      jm.H[j](0, SG) -= ds.dsgx / n;
    }
}

void Navigator::position_measurement(int i, JointMeasurement& jm) const {
  // dz_i = r_o^i - sum_j k_j r_o^j (eq. 9, 12) depends on every subsystem's state:
  // (1 - k_i) H_i in block i and -k_j H_j in the others, and, through the level a Wheel-INS
  // uses in C_v^w (eq. 8), on the Body-INS attitude.
  const int N = subsystem_count();
  Vec3 level = Vec3::Zero();
  const bool shared = body_ && opt_.fusion.share_level;
  if (shared) level = body_->vehicle_rpy();
  Vec3 fused = Vec3::Zero(), own = Vec3::Zero();
  for (int j = 0; j < kMaxCentralized; ++j) jm.H[j].setZero();
  for (int j = 0; j < N; ++j) {
    ReferencePointInput in = subs_[j]->reference_point_input();
    if (shared && in.wheel) {
      in.vehicle_roll = level.x();
      in.vehicle_pitch = level.y();
    }
    const ReferencePointModel m = reference_point_model(in);
    const double c = (j == i ? 1.0 : 0.0) - weights_[j];
    jm.H[j] += c * m.H;
    if (in.wheel) add_level_block(m.H_level, c, jm.H);
    fused += weights_[j] * m.r_o;
    if (j == i) own = m.r_o;
  }
  jm.dz = own - fused;
  const double sd = opt_.fusion.position_std;
  jm.R = Mat3::Identity() * sd * sd;
  jm.gate = opt_.fusion.position_gate;
}

UpdateReport Navigator::fuse_joint(const JointMeasurement& m) {
  std::array<const H3*, kMaxCentralized> blocks{};
  for (int j = 0; j < subsystem_count(); ++j) blocks[j] = &m.H[j];
  std::array<Vec21, kMaxCentralized> dx;
  const UpdateReport rep = joint_->update(blocks, m.dz, m.R, m.gate, dx);
  if (rep.accepted)
    for (int j = 0; j < subsystem_count(); ++j) subs_[j]->ekf().feedback(dx[j]);
  return rep;
}

void Navigator::velocity_updates_centralized() {
  // Sequential updates, each evaluated at the state the previous one left (the joint
  // correction moves every IMU's errors).
  JointMeasurement& m = joint_scratch_;
  for (int i = 0; i < subsystem_count(); ++i) {
    share_level();
    velocity_measurement(i, m);
    const UpdateReport rep = fuse_joint(m);
    ++stats_.velocity_updates;
    if (!rep.accepted) ++stats_.velocity_rejected;
    stats_.max_velocity_test_ratio = std::max(stats_.max_velocity_test_ratio, rep.test_ratio);
  }
}

void Navigator::velocity_updates() {
  if (joint_) {
    velocity_updates_centralized();
    return;
  }
  // Shared information (Section III): vehicle level from the Body-INS, wheel speed.
  share_level();
  const double n = static_cast<double>(wheels_.size());
  double mean_speed = 0.0;
  Vec3 mean_point = Vec3::Zero();
  for (WheelIns* w : wheels_) {
    mean_speed += w->wheel_speed() / n;
    mean_point += w->module().p_inV / n;
  }
  auto count = [&](const UpdateReport& rep) {
    ++stats_.velocity_updates;
    if (!rep.accepted) ++stats_.velocity_rejected;
    stats_.max_velocity_test_ratio = std::max(stats_.max_velocity_test_ratio, rep.test_ratio);
  };
  for (int i = 0; i < subsystem_count(); ++i) {
    if (subs_[i]->is_wheel()) {
      const auto& w = static_cast<const WheelIns&>(*subs_[i]);
      WheelVelocityInput in = w.own_velocity_input();
      if (opt_.fusion.speed == SpeedSharing::kMean && wheels_.size() > 1) {
        // Its own speed enters the mean with weight 1/n.
        in.measured_speed = mean_speed;
        in.dspeed_dbgx /= n;
        in.dspeed_dsgx /= n;
      }
      const WheelVelocityModel m = wheel_velocity_model(in);
      count(fuse(i, m.H, m.innovation(), w.velocity_noise(), w.velocity_gate()));
    } else {
      // The mean speed of the wheels is the speed of the mean of their centres (o for a
      // symmetric pair; the wheel centre itself for one wheel).
      const BodyVelocityModel m = body_->velocity_model(mean_speed, mean_point);
      count(fuse(i, m.H, m.innovation(), body_->velocity_noise(), body_->velocity_gate()));
    }
  }
}

UpdateReport Navigator::fuse(int i, const H3& H, const Vec3& dz, const Mat3& R, double gate) {
  if (!joint_) return subs_[i]->ekf().update<3>(H, dz, R, gate);
  std::array<const H3*, kMaxCentralized> blocks{};
  blocks[i] = &H;
  std::array<Vec21, kMaxCentralized> dx;
  const UpdateReport rep = joint_->update(blocks, dz, R, gate, dx);
  if (rep.accepted)
    for (int j = 0; j < subsystem_count(); ++j) subs_[j]->ekf().feedback(dx[j]);
  return rep;
}

Mat21 Navigator::covariance(int i) const {
  return joint_ ? joint_->block(i) : subs_[i]->ekf().covariance();
}

void Navigator::position_update() {
  if (joint_) {
    // Sequentially, each re-evaluated at the state the previous one left.
    JointMeasurement& m = joint_scratch_;
    for (int i = 0; i < subsystem_count(); ++i) {
      share_level();
      position_measurement(i, m);
      const UpdateReport rep = fuse_joint(m);
      ++stats_.position_updates;
      if (!rep.accepted) ++stats_.position_rejected;
      stats_.max_position_test_ratio = std::max(stats_.max_position_test_ratio, rep.test_ratio);
    }
    return;
  }
  // Algorithm 1: o in every subsystem's frame, their weighted mean as the measurement.
  std::vector<ReferencePointModel>& models = rp_models_;
  Vec3 fused = Vec3::Zero();
  for (std::size_t i = 0; i < subs_.size(); ++i) {
    models[i] = reference_point_model(subs_[i]->reference_point_input());
    fused += weights_[i] * models[i].r_o;
  }
  const double sd = opt_.fusion.position_std;
  const Mat3 R = Mat3::Identity() * sd * sd;
  for (std::size_t i = 0; i < subs_.size(); ++i) {
    const Vec3 dz = models[i].r_o - fused;
    const UpdateReport rep =
        subs_[i]->ekf().update<3>(models[i].H, dz, R, opt_.fusion.position_gate);
    ++stats_.position_updates;
    if (!rep.accepted) ++stats_.position_rejected;
    stats_.max_position_test_ratio = std::max(stats_.max_position_test_ratio, rep.test_ratio);
  }
}

TrajectoryRecord Navigator::subsystem_record(int i) const {
  const Subsystem& s = *subs_[i];
  const StrapdownEkf& ekf = s.ekf();
  const Mat21 P = covariance(i);
  TrajectoryRecord r;
  r.t = ekf.state().t;
  const ReferencePointModel m = reference_point_model(s.reference_point_input());
  r.p_inN = m.r_o;
  r.lla = frame_.geodetic_from_ned(r.p_inN);
  r.v_inN = s.reference_velocity_inW();
  const Eigen::RowVector3d J = s.heading_sensitivity();
  const double var_psi = J * P.block<3, 3>(PHI, PHI) * J.transpose();
  if (!s.is_wheel()) {
    r.rpy = static_cast<const BodyIns&>(s).vehicle_rpy();
    r.rpy_std.head<2>() = P.block<2, 2>(PHI, PHI).diagonal().cwiseSqrt();
  } else {
    r.rpy = Vec3(0.0, 0.0, s.vehicle_heading());
    if (body_ && opt_.fusion.share_level) r.rpy.head<2>() = body_->vehicle_rpy().head<2>();
  }
  r.rpy_std.z() = std::sqrt(std::max(0.0, var_psi));
  r.p_std = (m.H * P * m.H.transpose()).diagonal().cwiseSqrt();
  r.v_std = P.block<3, 3>(V, V).diagonal().cwiseSqrt();
  const ImuErrors& e = ekf.errors();
  r.bg = e.bg;
  r.ba = e.ba;
  r.sg = e.sg;
  r.sa = e.sa;
  r.bg_std = P.block<3, 3>(BG, BG).diagonal().cwiseSqrt();
  r.ba_std = P.block<3, 3>(BA, BA).diagonal().cwiseSqrt();
  r.sg_std = P.block<3, 3>(SG, SG).diagonal().cwiseSqrt();
  r.sa_std = P.block<3, 3>(SA, SA).diagonal().cwiseSqrt();
  return r;
}

TrajectoryRecord Navigator::vehicle_record() const {
  TrajectoryRecord r = subsystem_record(0);
  if (subs_.size() == 1) return r;
  // Output as in the paper: the fused reference point and the mean heading. The 1-sigma
  // of a weighted mean is bounded by the weighted mean of the sigmas whatever the
  // correlation between subsystems (Minkowski), which is what is reported.
  Vec3 p = Vec3::Zero(), v = Vec3::Zero(), p_std = Vec3::Zero(), v_std = Vec3::Zero();
  double s = 0.0, c = 0.0, psi_std = 0.0;
  for (int i = 0; i < subsystem_count(); ++i) {
    const TrajectoryRecord ri = subsystem_record(i);
    const double k = weights_[i];
    p += k * ri.p_inN;
    v += k * ri.v_inN;
    p_std += k * ri.p_std;
    v_std += k * ri.v_std;
    s += k * std::sin(ri.rpy.z());
    c += k * std::cos(ri.rpy.z());
    psi_std += k * ri.rpy_std.z();
  }
  r.p_inN = p;
  r.lla = frame_.geodetic_from_ned(p);
  r.v_inN = v;
  r.p_std = p_std;
  r.v_std = v_std;
  r.rpy.z() = std::atan2(s, c);
  r.rpy_std.z() = psi_std;
  if (body_) {
    const Vec3 rpy = body_->vehicle_rpy();
    r.rpy.head<2>() = rpy.head<2>();
  }
  return r;
}

}  // namespace wheelins
