#include "wheelins/fusion/navigator.hpp"

#include <cmath>
#include <sstream>

namespace wheelins {

std::string NavigatorOptions::describe() const {
  std::ostringstream o;
  o << "velocity update interval: " << wheel.velocity_update_interval << " s\n"
    << "wheel speed window:       " << wheel.speed_window << " s\n"
    << "velocity noise (fwd/lat/vert): " << wheel.velocity_std.transpose() << " m/s\n"
    << "innovation gate:          "
    << (wheel.gate > 0 ? std::to_string(wheel.gate) : std::string("off")) << "\n"
    << "initial sigma: position " << wheel.init.position << " m, velocity "
    << wheel.init.velocity << " m/s, roll/pitch " << wheel.init.roll_pitch / kDeg
    << " deg, heading " << wheel.init.heading / kDeg << " deg\n"
    << "mechanization:            "
    << (mechanization == MechanizationOptions::Method::kRotationExact ? "rotation-exact"
                                                                       : "classic two-sample")
    << "\n"
    << "earth rotation:           " << (earth_rotation ? "compensated" : "ignored") << "\n"
    << "output interval:          "
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
    if (m->kind != ModuleKind::kWheel)
      throw InputError("module '" + name +
                       "' is a Body-IMU: this build's navigator runs Wheel-IMUs only "
                       "(Body-INS arrives with the multi-IMU fusion)");
    wheels_.push_back(std::make_unique<WheelIns>(*m, opt_.wheel, mech));
  }
  static_.resize(wheels_.size());
}

Navigator::~Navigator() = default;

void Navigator::process(int index, const ImuSample& raw) {
  ++stats_.samples;
  WheelIns& w = *wheels_[index];
  const ImuSample b = w.to_body(raw);
  if (!navigating_) {
    if (raw.t <= manifest_.static_start) return;
    if (raw.t <= manifest_.static_end + 1e-9) {
      static_[index].add(b);
      return;
    }
    start_navigation(raw.t - raw.dt);
  }
  w.propagate(b);
  if (index != 0) return;
  ++stats_.epochs;
  if (w.velocity_update_due()) {
    const UpdateReport rep = w.velocity_update(w.own_velocity_input());
    ++stats_.velocity_updates;
    if (!rep.accepted) ++stats_.velocity_rejected;
    stats_.max_velocity_test_ratio = std::max(stats_.max_velocity_test_ratio, rep.test_ratio);
  }
  stats_.t_end = raw.t;
  if (raw.t + 1e-9 >= next_output_t_) {
    sink_(make_record());
    ++stats_.records;
    if (opt_.output_interval > 0)
      while (next_output_t_ <= raw.t + 1e-9) next_output_t_ += opt_.output_interval;
  }
}

void Navigator::start_navigation(double t0) {
  for (std::size_t i = 0; i < wheels_.size(); ++i) {
    if (static_[i].count() < 10)
      throw InputError("module '" + wheels_[i]->module().name + "': only " +
                       std::to_string(static_[i].count()) +
                       " samples in the static period [" + std::to_string(manifest_.static_start) +
                       ", " + std::to_string(manifest_.static_end) +
                       "] s: the alignment needs a static period covered by the data");
    wheels_[i]->start(static_[i], manifest_.initial_heading, t0);
  }
  navigating_ = true;
  stats_.t_start = t0;
  next_output_t_ = t0;
}

TrajectoryRecord Navigator::make_record() const {
  const WheelIns& w = *wheels_[0];
  const StrapdownEkf& ekf = w.ekf();
  const Mat21& P = ekf.covariance();
  TrajectoryRecord r;
  r.t = ekf.state().t;
  r.p_inN = w.reference_point_inW();
  r.lla = frame_.geodetic_from_ned(r.p_inN);
  r.v_inN = w.reference_velocity_inW();
  r.rpy = Vec3(0.0, 0.0, w.vehicle_heading());
  r.p_std = P.block<3, 3>(StateIndex::P, StateIndex::P).diagonal().cwiseSqrt();
  r.v_std = P.block<3, 3>(V, V).diagonal().cwiseSqrt();
  // Heading sigma through d(psi)/d(phi) of the Wheel-IMU x-axis (wheel_velocity.cpp).
  const Vec3 c1 = ekf.state().C_ItoW().col(0);
  const double h2 = c1.x() * c1.x() + c1.y() * c1.y();
  const Eigen::RowVector3d J = Eigen::RowVector3d(-c1.y() / h2, c1.x() / h2, 0.0) * skew(c1);
  const double var_psi = J * P.block<3, 3>(PHI, PHI) * J.transpose();
  r.rpy_std = Vec3(0.0, 0.0, std::sqrt(std::max(0.0, var_psi)));
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

}  // namespace wheelins
