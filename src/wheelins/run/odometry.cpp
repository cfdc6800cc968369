// Wheel odometry with a gyro heading: the naive baseline (odometry.hpp).
#include "wheelins/run/odometry.hpp"

#include <cmath>
#include <memory>

#include "wheelins/io/imu_file.hpp"
#include "wheelins/io/text_util.hpp"

namespace wheelins {

namespace {

// The modules a request uses: its wheels and the body IMU of its gyro (or none).
struct OdometryModules {
  std::vector<const ModuleSpec*> wheels;
  const ModuleSpec* gyro = nullptr;
  /// The wheels, then the gyro: the order of the merged streams.
  std::vector<const ModuleSpec*> all() const {
    std::vector<const ModuleSpec*> modules = wheels;
    if (gyro) modules.push_back(gyro);
    return modules;
  }
};

// Finds the request's modules in the manifest (`man`: its quoted path); InputError for a module
// that is not what it is used as, or for no source of a heading.
OdometryModules resolve_modules(const OdometryRequest& r, const std::string& man) {
  const Manifest& m = r.manifest;
  if (r.wheels.empty()) throw InputError("odometry: no wheel module given");
  OdometryModules mods;
  std::vector<const ModuleSpec*>& specs = mods.wheels;
  for (const auto& name : r.wheels) {
    const ModuleSpec* s = m.find(name);
    if (!s) throw InputError(man + ": no module named '" + name + "'");
    if (s->kind != ModuleKind::kWheel) throw InputError(man + ": module '" + name + "' is not a wheel IMU");
    specs.push_back(s);
  }
  if (!r.gyro.empty()) {
    mods.gyro = m.find(r.gyro);
    if (!mods.gyro) throw InputError(man + ": no module named '" + r.gyro + "'");
    if (mods.gyro->kind != ModuleKind::kBody) throw InputError(man + ": module '" + r.gyro + "' is not a body IMU");
  } else if (specs.size() < 2 || std::abs(specs[0]->p_inV.y() - specs[1]->p_inV.y()) < 0.05) {
    throw InputError("odometry: a heading needs a body IMU (the gyro) or two wheels on opposite sides");
  }
  return mods;
}

// The merged samples of the modules, in the order given.
ImuMerger open_modules(const Manifest& m, const std::vector<const ModuleSpec*>& all) {
  std::vector<std::unique_ptr<ImuStream>> streams;
  for (const ModuleSpec* s : all)
    streams.push_back(std::make_unique<ImuFileReader>(m.resolve(s->file), imu_read_options(*s)));
  return ImuMerger(std::move(streams));
}

// The rotation from each module's sensor axes to the body axes.
std::vector<Mat3> sensor_to_body(const std::vector<const ModuleSpec*>& all) {
  std::vector<Mat3> C(all.size());
  for (std::size_t i = 0; i < all.size(); ++i)
    C[i] = all[i]->kind == ModuleKind::kWheel ? wheel_sensor_to_body(*all[i]) : dcm_from_euler(all[i]->mounting_rpy);
  return C;
}

// The yaw rate (counter-clockwise from above) and the speed at o of one step.
struct Motion {
  double yaw_up = 0.0;
  double vo = 0.0;
};

// The dead reckoning: every module's latest rate and its bias at rest, the position and the
// heading integrated so far, the records given.
class OdometryIntegrator {
 public:
  OdometryIntegrator(const OdometryRequest& r, const OdometryModules& mods);
  /// Takes module k's sample; false while at rest (the sample goes into the module's bias).
  bool add(std::size_t k, const ImuSample& s);
  /// One step to the first wheel's sample at t, with every module's latest sample up to t.
  void step(double t);
  bool started() const { return started_; }
  const OdometryResult& result() const { return out_; }

 private:
  Vec3 body_rate(std::size_t i) const;
  Motion motion() const;
  void advance(double t, const Motion& mv);
  void emit(double t, double vo);

  const OdometryRequest& r_;
  const OdometryModules& mods_;
  std::vector<Mat3> C_;
  std::vector<Vec3> bias_sum_, rate_;
  std::vector<double> bias_n_;
  std::vector<bool> seen_;
  earth::LocalFrame frame_;
  OdometryResult out_;
  double psi_, t_prev_ = 0.0, next_out_ = -1e300;
  Vec3 p_ = Vec3::Zero();
  bool started_ = false;
};

OdometryIntegrator::OdometryIntegrator(const OdometryRequest& r, const OdometryModules& mods)
    : r_(r),
      mods_(mods),
      C_(sensor_to_body(mods.all())),
      bias_sum_(C_.size(), Vec3::Zero()),
      rate_(C_.size(), Vec3::Zero()),
      bias_n_(C_.size(), 0.0),
      seen_(C_.size(), false),
      frame_(r.manifest.origin),
      psi_(r.manifest.initial_heading) {
  const auto& specs = mods.wheels;
  out_.heading_source = mods.gyro ? "the gyro of " + mods.gyro->name
                                  : "the speed difference of " + specs[0]->name + " and " + specs[1]->name;
}

bool OdometryIntegrator::add(std::size_t k, const ImuSample& s) {
  const Manifest& m = r_.manifest;
  rate_[k] = s.dtheta / s.dt;
  seen_[k] = true;
  if (s.t <= m.static_end) {
    if (s.t >= m.static_start) bias_sum_[k] += rate_[k], bias_n_[k] += 1.0;
    return false;
  }
  return true;
}

Vec3 OdometryIntegrator::body_rate(std::size_t i) const {
  const Vec3 b = bias_n_[i] > 0.0 ? Vec3(bias_sum_[i] / bias_n_[i]) : Vec3::Zero();
  return Vec3(C_[i] * (rate_[i] - b));
}

Motion OdometryIntegrator::motion() const {
  const auto& specs = mods_.wheels;
  const std::size_t nw = specs.size();
  // Speeds of the wheels, the yaw rate (counter-clockwise from above), the speed at o.
  std::vector<double> v(nw);
  for (std::size_t i = 0; i < nw; ++i)
    v[i] = -specs[i]->axle_sign * (specs[i]->odometry_radius > 0.0 ? specs[i]->odometry_radius : specs[i]->wheel_radius) *
           body_rate(i).x();
  Motion mv;
  mv.yaw_up = mods_.gyro ? -body_rate(nw).z() : (v[1] - v[0]) / (specs[1]->p_inV.y() - specs[0]->p_inV.y());
  for (std::size_t i = 0; i < nw; ++i) mv.vo += v[i] - mv.yaw_up * specs[i]->p_inV.y();
  mv.vo /= static_cast<double>(nw);
  return mv;
}

void OdometryIntegrator::advance(double t, const Motion& mv) {
  if (!started_) {
    started_ = true;
    t_prev_ = t;
    out_.t_start = t;
  }
  const double dt = t - t_prev_;
  t_prev_ = t;
  const double psi_mid = psi_ - 0.5 * mv.yaw_up * dt;
  p_ += Vec3(std::cos(psi_mid), std::sin(psi_mid), 0.0) * mv.vo * dt;
  psi_ = wrap_pi(psi_ - mv.yaw_up * dt);
  out_.distance += std::abs(mv.vo) * dt;
  out_.t_end = t;
}

void OdometryIntegrator::emit(double t, double vo) {
  TrajectoryRecord rec;
  rec.t = t;
  rec.p_inN = p_;
  rec.lla = frame_.geodetic_from_ned(p_);
  rec.v_inN = Vec3(std::cos(psi_), std::sin(psi_), 0.0) * vo;
  rec.rpy = Vec3(0.0, 0.0, psi_);
  rec.p_std = rec.v_std = rec.rpy_std = Vec3::Constant(std::nan(""));
  ++out_.records;
  if (r_.on_record) r_.on_record(rec);
}

void OdometryIntegrator::step(double t) {
  bool all_seen = true;
  for (bool x : seen_) all_seen = all_seen && x;
  if (!all_seen) return;
  const Motion mv = motion();
  advance(t, mv);
  if (t + 1e-9 < next_out_) return;
  next_out_ = t + r_.output_interval;
  emit(t, mv.vo);
}

}  // namespace

OdometryResult run_wheel_odometry(const OdometryRequest& r) {
  const std::string man = io_detail::quote(r.manifest.path);
  const OdometryModules mods = resolve_modules(r, man);
  ImuMerger merger = open_modules(r.manifest, mods.all());
  OdometryIntegrator odo(r, mods);
  // The first wheel's samples drive the integration; a step is taken once the merged
  // samples have passed its time (the other modules' samples of the same time come after
  // it: the merger gives equal times in module order).
  bool pending = false;
  double pending_t = 0.0;
  std::size_t k = 0;
  ImuSample s;
  while (merger.next(k, s)) {
    if (pending && s.t > pending_t) {
      odo.step(pending_t);
      pending = false;
    }
    if (odo.add(k, s) && k == 0) {
      pending = true;
      pending_t = s.t;
    }
  }
  if (pending) odo.step(pending_t);
  if (!odo.started())
    throw InputError(man + ": the data end before the static period does: nothing to dead-reckon");
  return odo.result();
}

}  // namespace wheelins
