#include "wheelins/sim/simulator.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <exception>
#include <limits>
#include <sstream>
#include <thread>

#include "wheelins/io/atomic_file.hpp"
#include "wheelins/io/binary.hpp"
#include "wheelins/io/truth.hpp"
#include "wheelins/nav/types.hpp"
#include "wheelins/sim/faults.hpp"
#include "wheelins/util/interrupt.hpp"
#include "wheelins/util/progress.hpp"

namespace wheelins::sim {
namespace fs = std::filesystem;
namespace {

// 4-point Gauss-Legendre on [-1, 1].
constexpr double kGlX[4] = {-0.86113631159405257522, -0.33998104358485626480,
                            0.33998104358485626480, 0.86113631159405257522};
constexpr double kGlW[4] = {0.34785484513745385737, 0.65214515486254614263,
                            0.65214515486254614263, 0.34785484513745385737};

/// A[g][j] = integral from -1 to x_g of the Lagrange basis polynomial L_j through the
/// four nodes: alpha(node g) = alpha(start) + h/2 sum_j A[g][j] alpha_dot(node j).
struct LagrangeIntegrals {
  double A[4][4];
  LagrangeIntegrals() {
    for (int j = 0; j < 4; ++j) {
      // Coefficients of L_j(x) = prod_{m != j} (x - x_m) / (x_j - x_m), low order first.
      double c[4] = {1, 0, 0, 0};
      double denom = 1.0;
      int deg = 0;
      for (int m = 0; m < 4; ++m) {
        if (m == j) continue;
        for (int d = deg + 1; d >= 0; --d) c[d] = (d > 0 ? c[d - 1] : 0.0) - kGlX[m] * c[d];
        ++deg;
        denom *= kGlX[j] - kGlX[m];
      }
      for (int g = 0; g < 4; ++g) {
        auto prim = [&](double x) {
          double s = 0.0, p = x;
          for (int d = 0; d < 4; ++d) {
            s += c[d] * p / (d + 1);
            p *= x;
          }
          return s;
        };
        A[g][j] = (prim(kGlX[g]) - prim(-1.0)) / denom;
      }
    }
  }
};
const LagrangeIntegrals kLagrange;

/// The ideal wheel b-frame in the v-frame at wheel angle 0: b_x -> v_y, b_y -> -v_x, b_z -> v_z.
Mat3 wheel_c0() {
  Mat3 C;
  C << 0, -1, 0, 1, 0, 0, 0, 0, 1;
  return C;
}

std::string num(double x) {
  char buf[40];
  const int int_digits = std::abs(x) >= 1.0 && std::abs(x) < 1e17
                             ? static_cast<int>(std::floor(std::log10(std::abs(x)))) + 1
                             : 1;
  for (int p = std::max(1, int_digits); p <= 17; ++p) {
    std::snprintf(buf, sizeof buf, "%.*g", p, x);
    if (std::strtod(buf, nullptr) == x) break;
  }
  return buf;
}
std::string vec(const Vec3& v, double unit = 1.0) {
  return "[" + num(v.x() / unit) + ", " + num(v.y() / unit) + ", " + num(v.z() / unit) + "]";
}

double round_to(double x, double lsb) { return std::nearbyint(x / lsb) * lsb; }

}  // namespace

// ---------------------------------------------------------------------------------------------
// Vibration

void Vibration::eval(double t, JV& disp, JV& rot) const {
  for (int d = 0; d < 6; ++d) {
    J acc(0.0);
    for (const auto& c : dof[d]) {
      const double th = c.omega * t + c.phase;
      const double s = std::sin(th), co = std::cos(th), w = c.omega, a = c.amplitude;
      acc.c[0] += a * s;
      if constexpr (kOrder >= 1) acc.c[1] += a * w * co;
      if constexpr (kOrder >= 2) acc.c[2] -= a * w * w * s / 2.0;
      if constexpr (kOrder >= 3) acc.c[3] -= a * w * w * w * co / 6.0;
    }
    (d < 3 ? disp[d] : rot[d - 3]) = acc;
  }
}

void Vibration::prepare(const double offsets[4], double h) {
  step_h = h;
  since_exact = -1;
  for (int d = 0; d < 6; ++d) {
    node_phasors[d].clear();
    phase_state[d].clear();
    for (const auto& c : dof[d]) phase_state[d].push_back({0.0, 0.0, std::cos(c.omega * h), std::sin(c.omega * h)});
    for (const auto& c : dof[d]) {
      std::array<double, 8> ph;
      for (int i = 0; i < 4; ++i) {
        ph[2 * i] = std::cos(c.omega * offsets[i]);
        ph[2 * i + 1] = std::sin(c.omega * offsets[i]);
      }
      node_phasors[d].push_back(ph);
    }
  }
}

void Vibration::eval4(double t_mid, JV disp[4], JV rot[4]) {
  const bool exact = since_exact < 0 || since_exact >= 255 ||
                     std::abs(t_mid - last_mid - step_h) > 1e-9 * step_h;
  since_exact = exact ? 0 : since_exact + 1;
  last_mid = t_mid;
  for (int d = 0; d < 6; ++d) {
    J acc[4];
    for (std::size_t k = 0; k < dof[d].size(); ++k) {
      const Component& c = dof[d][k];
      const auto& ph = node_phasors[d][k];
      auto& st = phase_state[d][k];
      if (exact) {
        const double th = c.omega * t_mid + c.phase;
        st[0] = std::sin(th);
        st[1] = std::cos(th);
      } else {
        const double sn = st[0] * st[2] + st[1] * st[3];
        st[1] = st[1] * st[2] - st[0] * st[3];
        st[0] = sn;
      }
      const double s0 = st[0], c0 = st[1], w = c.omega, a = c.amplitude;
      for (int i = 0; i < 4; ++i) {
        const double s = s0 * ph[2 * i] + c0 * ph[2 * i + 1];  // sin(th + w off_i)
        const double co = c0 * ph[2 * i] - s0 * ph[2 * i + 1];
        acc[i].c[0] += a * s;
        if constexpr (kOrder >= 1) acc[i].c[1] += a * w * co;
        if constexpr (kOrder >= 2) acc[i].c[2] -= a * w * w * s / 2.0;
        if constexpr (kOrder >= 3) acc[i].c[3] -= a * w * w * w * co / 6.0;
      }
    }
    for (int i = 0; i < 4; ++i) (d < 3 ? disp[i][d] : rot[i][d - 3]) = acc[i];
  }
}

Vibration Vibration::draw(Rng& rng, const Vec3& accel_rms, const Vec3& rate_rms, const double band[2],
                          int components) {
  Vibration v;
  const double share = std::sqrt(2.0 / components);  // sum of K sines of amplitude A: RMS A sqrt(K/2)
  for (int d = 0; d < 6; ++d) {
    const double rms = d < 3 ? accel_rms[d] : rate_rms[d - 3];
    for (int i = 0; i < components; ++i) {
      Component c;
      c.omega = 2.0 * kPi * rng.uniform(band[0], band[1]);
      c.phase = rng.uniform(0.0, 2.0 * kPi);
      // Displacement amplitude from the acceleration amplitude (/ w^2); angle from rate (/ w).
      c.amplitude = rms * share / (d < 3 ? c.omega * c.omega : c.omega);
      if (rms > 0.0) v.dof[d].push_back(c);
    }
  }
  return v;
}

// ---------------------------------------------------------------------------------------------
// Kinematics of one module

namespace {

/// Forward rolling rate of a wheel, d alpha / dt at time t, as a jet in t:
///   alpha_dot = v_wc (1 + slip_coeff a_wc + sum_i s_i w_i(t)) / R,
/// v_wc the forward speed of the wheel centre, a_wc its derivative (valid to order kOrder - 2
/// with the slip effect: the top coefficient of a_wc is lost), s_i and w_i the ratio and the
/// C-infinity window of each slip fault (exact jets in t, sim/faults.hpp).
J wheel_rate_jet(const ModuleModel& m, double t, const JV& p_o, const JM& C_v) {
  const JV pwc = p_o + C_v * m.truth.p_inV;
  const J vf = dot(C_v.col(0), pwc.dot());
  // The windows vanish with all derivatives outside (t0, t1): there the fault-free
  // expressions below are used, so the data outside the events are bit for bit unchanged.
  J fault(0.0);
  bool any = false;
  for (const auto& e : m.slip_events)
    if (t > e.t0 && t < e.t1) {
      fault += e.ratio * slip_window<kOrder>(t, e.t0, e.t1);
      any = true;
    }
  if (any) {
    const J slip = m.slip_coeff == 0.0 ? J(0.0) : m.slip_coeff * vf.dot();
    return vf * (1.0 + slip + fault) / m.radius;
  }
  if (m.slip_coeff == 0.0) return vf / m.radius;
  const J af = vf.dot();
  return vf * (1.0 + m.slip_coeff * af) / m.radius;
}

/// Forward speed of a wheel centre (rigid motion, no slip) at a time, from the v-frame jets.
double wheel_centre_speed_of(const ModuleModel& m, const JV& p_o, const JM& C_v) {
  const JV pwc = p_o + C_v * m.truth.p_inV;
  return dot(C_v.col(0), pwc.dot()).value();
}

/// Vibration gain from the speed of o (see ModuleModel::vib_cruise_speed).
J vibration_gain(const ModuleModel& m, const JV& p_o) {
  const JV v = p_o.dot();
  const double v0 = 0.3 * m.vib_cruise_speed;
  const J x = dot(v, v) / (v0 * v0);
  const double xc = 1.0 / 0.09;  // x at the cruise speed
  return x / (1.0 + x) * ((1.0 + xc) / xc);
}

/// The same gain as a plain number, from the speed of o [m/s].
double vibration_gain(const ModuleModel& m, double speed) {
  const double v0 = 0.3 * m.vib_cruise_speed;
  const double x = speed * speed / (v0 * v0);
  const double xc = 1.0 / 0.09;
  return x / (1.0 + x) * ((1.0 + xc) / xc);
}

void scale(JV& a, const J& g) {
  for (int i = 0; i < 3; ++i) a[i] = a[i] * g;
}

struct NodeResult {
  Vec3 gyro, accel;
};

}  // namespace

/// Steps one module through the sample grid on its own (possibly offset) clock.
class GroupStepper {
 public:
  GroupStepper(const Simulation& sim, int g, double offset)
      : sim_(sim), m_(sim.modules_[g]), offset_(offset), wheel_(m_.truth.wheel),
        vib_(m_.vibration), h_(1.0 / sim.cfg_.rate_hz) {
    C0_ = wheel_c0();
    C_sb_ = dcm_from_euler(m_.truth.mounting_rpy);
    for (int i = 0; i < 4; ++i) node_offset_[i] = 0.5 * h_ * kGlX[i];
    if (!vib_.empty()) vib_.prepare(node_offset_, h_);
    if (wheel_ && offset != 0.0) {
      // alpha is zero at the scenario start; integrate to the offset start.
      const double a = sim.start_time(), b = a + offset;
      for (int i = 0; i < 4; ++i) {
        const double t = 0.5 * (a + b) + 0.5 * (b - a) * kGlX[i];
        alpha_ += 0.5 * (b - a) * kGlW[i] * rate_at(t).value();
      }
    }
  }

  /// Mean gyro / accel (sensor axes) over the stamped interval (t1 - 1/rate, t1]. (The
  /// nominal interval length is used: stamps t0 + k/rate differ from it by rounding only.)
  void step(double t1, Vec3& gyro, Vec3& accel) {
    const double h = h_;
    const double mid = t1 + offset_ - 0.5 * h;
    JV p_o[4];
    JM C_v[4];
    J rate[4];
    double t[4];
    JV disp[4], rot[4];
    if (!vib_.empty()) vib_.eval4(mid, disp, rot);
    for (int i = 0; i < 4; ++i) {
      t[i] = mid + node_offset_[i];
      sim_.scenario_->evaluate(t[i], p_o[i], C_v[i]);
      if (wheel_) rate[i] = wheel_rate_jet(m_, t[i], p_o[i], C_v[i]);
      if (!vib_.empty()) {
        const J gain = vibration_gain(m_, p_o[i]);
        scale(disp[i], gain);
        scale(rot[i], gain);
      }
    }
    gyro.setZero();
    accel.setZero();
    for (int i = 0; i < 4; ++i) {
      J alpha(0.0);
      if (wheel_) {
        double ai = alpha_;
        for (int j = 0; j < 4; ++j) ai += 0.5 * h * kLagrange.A[i][j] * rate[j].value();
        alpha = integrate(ai, rate[i]);
      }
      const NodeResult r = node(t[i], p_o[i], C_v[i], alpha, vib_.empty() ? nullptr : &disp[i],
                                vib_.empty() ? nullptr : &rot[i]);
      gyro += 0.5 * kGlW[i] * r.gyro;
      accel += 0.5 * kGlW[i] * r.accel;
    }
    if (wheel_)
      for (int j = 0; j < 4; ++j) alpha_ += 0.5 * h * kGlW[j] * rate[j].value();
  }

  J rate_at(double t) const {
    JV p;
    JM C;
    sim_.scenario_->evaluate(t, p, C);
    return wheel_rate_jet(m_, t, p, C);
  }

  static J integrate(double value, const J& rate) {
    J a(value);
    for (int k = 1; k <= kOrder; ++k) a.c[k] = rate.c[k - 1] / k;
    return a;
  }

  /// Position and attitude (sensor axes) jets of the IMU.
  void imu_jets(double t, const JV& p_o, const JM& C_v, const J& alpha, JV& p, JM& C_s,
                const JV* vib_disp = nullptr, const JV* vib_rot = nullptr) const {
    JV disp(Vec3::Zero()), rot(Vec3::Zero());
    if (vib_disp) {
      disp = *vib_disp;
      rot = *vib_rot;
    } else if (!m_.vibration.empty()) {
      m_.vibration.eval(t, disp, rot);
      const J gain = vibration_gain(m_, p_o);
      scale(disp, gain);
      scale(rot, gain);
    }
    const JV offset_v = JV(m_.truth.p_inV) + disp;
    if (wheel_) {
      const bool vib = vib_disp || !m_.vibration.empty();
      const JM C_wheel = C0_ * jrot_x(-alpha);
      const JM C_b = vib ? C_v * (jdcm_from_euler(rot[0], rot[1], rot[2]) * C_wheel)
                         : C_v * C_wheel;  // ideal wheel b-frame
      C_s = C_b * C_sb_;
      p = p_o + C_v * offset_v - C_b * m_.truth.lever_arm_inB;
    } else {
      if (vib_disp || !m_.vibration.empty()) {
        C_s = C_v * (jdcm_from_euler(rot[0], rot[1], rot[2]) * C_sb_);
      } else {
        C_s = C_v * C_sb_;
      }
      p = p_o + C_v * offset_v;
    }
  }

  NodeResult node(double t, const JV& p_o, const JM& C_v, const J& alpha, const JV* disp,
                  const JV* rot) const {
    JV p;
    JM C_s;
    imu_jets(t, p_o, C_v, alpha, p, C_s, disp, rot);
    const Mat3 C = C_s.value();
    const Vec3 v = p.deriv(1), acc = p.deriv(2);
    const Vec3 w = sim_.omega_ie_;
    NodeResult r;
    r.gyro = body_rate(C_s) + C.transpose() * w;
    r.accel = C.transpose() * (acc - Vec3(0, 0, sim_.gravity_) + 2.0 * w.cross(v));
    return r;
  }

 private:
  const Simulation& sim_;
  const ModuleModel& m_;
  double offset_;
  bool wheel_;
  Vibration vib_;  // a copy with the node phasors of this stepper
  double h_;
  double node_offset_[4];
  Mat3 C0_, C_sb_;
  double alpha_ = 0.0;
};

// ---------------------------------------------------------------------------------------------
// Simulation

namespace {
/// The typical (cruise) speed of a scenario: the mean speed while moving faster than 0.2 m/s.
double cruise_speed_of(const Scenario& s) {
  double sum = 0.0;
  int n = 0;
  for (double t = s.start_time(); t < s.end_time(); t += 1.0) {
    const double v = s.state(t).v_inN.norm();
    if (v > 0.2) sum += v, ++n;
  }
  return n > 0 ? sum / n : 1.0;
}
}  // namespace

const char* Simulation::group_name(int g) {
  static const char* n[] = {"left-wheel", "right-wheel", "body"};
  return n[g];
}
const char* Simulation::group_dir(int g) {
  static const char* n[] = {"left-wheel-imu", "right-wheel-imu", "body-imu"};
  return n[g];
}

Simulation::Simulation(const SimConfig& cfg) : cfg_(cfg) {
  cfg_.validate();
  const bool car = cfg_.vehicle.preset == "car";
  Terrain terrain;
  if (cfg_.terrain_slope_deg > 0.0) terrain = Terrain::gentle(cfg_.terrain_slope_deg, cfg_.seed);
  const double skid = cfg_.on("skid") ? cfg_.errors.skid_coeff : 0.0;
  if (cfg_.scenario == "default") {
    DefaultScenarioOptions o;
    if (cfg_.origin) o.origin = *cfg_.origin;
    if (cfg_.start_time) o.start_time = *cfg_.start_time;
    o.static_duration = cfg_.static_duration;
    o.laps = cfg_.laps;
    o.speed = cfg_.speed.value_or(car ? 6.0 : 1.4);
    o.scale = cfg_.loop_scale.value_or(car ? 4.0 : 1.0);
    o.path_sigma = cfg_.path_sigma.value_or(car ? 8.0 : 2.0);
    o.profile_sigma = cfg_.speed_sigma.value_or(car ? 2.5 : 1.2);
    o.stops = cfg_.stops;
    o.skid_coeff = skid;
    o.terrain = terrain;
    scenario_ = std::make_unique<PathScenario>(default_scenario_spec(o));
  } else {
    PathFileOptions o;
    o.speed_file = cfg_.speed_file;
    o.static_duration = cfg_.static_duration;
    o.speed = cfg_.speed.value_or(car ? 6.0 : 1.4);
    if (cfg_.start_time) o.start_time = *cfg_.start_time;
    o.path_sigma = cfg_.path_sigma.value_or(car ? 3.0 : 0.7);
    // An odometer profile is already smooth; a constant cruise speed needs the default's ramps.
    o.profile_sigma = cfg_.speed_sigma.value_or(cfg_.speed_file ? 0.5 : (car ? 2.5 : 1.2));
    o.origin = cfg_.origin;
    o.skid_coeff = skid;
    o.terrain = terrain;
    scenario_ = std::make_unique<PathScenario>(path_file_scenario_spec(cfg_.scenario, o, &speed_scale_));
  }
  const double cruise = cruise_speed_of(*scenario_);
  end_ = scenario_->end_time();
  if (cfg_.duration) end_ = std::min(end_, scenario_->start_time() + *cfg_.duration);
  const earth::Geodetic org = scenario_->origin();
  gravity_ = earth::normal_gravity(org.lat, org.h);
  omega_ie_ = cfg_.earth_rotation ? earth::earth_rate_ned(org.lat) : Vec3::Zero();

  // Modules: true geometry, manifest geometry, per-module physical draws.
  const ErrorParams& e = cfg_.errors;
  const ModuleGeometry* geo[kGroups] = {&cfg_.vehicle.left, &cfg_.vehicle.right, &cfg_.vehicle.body};
  for (int g = 0; g < kGroups; ++g) {
    ModuleModel& m = modules_[g];
    const std::string gn = group_name(g);
    m.truth = *geo[g];
    m.manifest = *geo[g];
    const bool wheel = m.truth.wheel;
    m.radius = m.radius_manifest = wheel ? cfg_.vehicle.wheel_radius : 0.0;
    {
      Rng r(cfg_.seed, gn + "/radius");
      const double d = r.normal(e.radius_rel);
      if (wheel && cfg_.on("radius")) m.radius = cfg_.vehicle.wheel_radius * (1.0 + d);
    }
    if (wheel && cfg_.on("slip")) m.slip_coeff = e.slip_coeff;
    {
      Rng r(cfg_.seed, gn + "/time_offset");
      const double d = r.normal(e.time_offset);
      if (cfg_.on("time_offset")) m.time_offset = d;
    }
    {
      Rng r(cfg_.seed, gn + "/temperature");
      const double d = e.temp_rise * (1.0 + 0.2 * r.normal());
      if (cfg_.on("temperature")) m.temp_rise = d;
    }
    {
      Rng r(cfg_.seed, gn + "/vibration");
      Vibration v = wheel ? Vibration::draw(r, e.vib_wheel_accel, e.vib_wheel_rate, e.vib_wheel_band)
                          : Vibration::draw(r, e.vib_body_accel, e.vib_body_rate, e.vib_body_band);
      if (cfg_.on("vibration")) m.vibration = std::move(v);
      m.vib_cruise_speed = cruise;
    }
    {
      Rng r(cfg_.seed, gn + "/calibration");
      Vec3 dl, dm, dp;
      for (int i = 0; i < 3; ++i) dl[i] = r.normal(e.cal_lever_arm);
      for (int i = 0; i < 3; ++i) dm[i] = r.normal(e.cal_mounting);
      for (int i = 0; i < 3; ++i) dp[i] = r.normal(e.cal_position);
      const double dr = r.normal(e.cal_radius_rel);
      if (cfg_.on("calibration")) {
        if (wheel) m.manifest.lever_arm_inB += dl;
        m.manifest.mounting_rpy += dm;
        m.manifest.p_inV += dp;
        if (wheel) m.radius_manifest *= 1.0 + dr;
      }
    }
    // Chips.
    for (int c = 1; c <= cfg_.chips; ++c) {
      ChipModel ch;
      ch.name = (g == 0 ? "left" : g == 1 ? "right" : "body") + std::string("-C") + std::to_string(c);
      auto draw3 = [&](const std::string& stream, double sigma) {
        Rng r(cfg_.seed, ch.name + "/" + stream);
        return Vec3(r.normal(sigma), r.normal(sigma), r.normal(sigma));
      };
      auto draw_T = [&](const std::string& stream, double sf, double mis, bool sf_on, bool mis_on) {
        Rng r(cfg_.seed, ch.name + "/" + stream);
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
      ch.gyro_bias = cfg_.on("gyro_bias") ? draw3("gyro_bias", e.gyro_bias) : z;
      ch.accel_bias = cfg_.on("accel_bias") ? draw3("accel_bias", e.accel_bias) : z;
      ch.gyro_gm0 = cfg_.on("gyro_gm") ? draw3("gyro_gm0", e.gyro_gm_sigma) : z;
      ch.accel_gm0 = cfg_.on("accel_gm") ? draw3("accel_gm0", e.accel_gm_sigma) : z;
      ch.gyro_T = draw_T("gyro_T", e.gyro_sf, e.gyro_misalign, cfg_.on("scale_factor"), cfg_.on("misalignment"));
      ch.accel_T = draw_T("accel_T", e.accel_sf, e.accel_misalign, cfg_.on("scale_factor"), cfg_.on("misalignment"));
      ch.gyro_tempco = cfg_.on("temperature") ? draw3("gyro_tempco", e.gyro_tempco) : z;
      ch.accel_tempco = cfg_.on("temperature") ? draw3("accel_tempco", e.accel_tempco) : z;
      chips_[g].push_back(ch);
    }
  }

  // Fault events: the targets must exist and the start must lie within the data. They use no
  // random draws. Slip faults become part of the wheel's motion (true time = start + time).
  const double span = data_duration();
  for (const FaultEvent& f : cfg_.faults) {
    const std::string what = "fault '" + f.spec() + "': ";
    if (f.target.find("-C") != std::string::npos) {
      const int n = std::stoi(f.target.substr(f.target.find("-C") + 2));
      if (n > cfg_.chips)
        throw InputError(what + "no chip " + f.target + " (the dataset has " + std::to_string(cfg_.chips) +
                         " chip" + (cfg_.chips == 1 ? "" : "s") + " per module: C1..C" +
                         std::to_string(cfg_.chips) + ")");
    }
    if (!(f.start < span))
      throw InputError(what + "the start " + num(f.start) + " s is outside the data (0 to " + num(span) +
                       " s since the start of the data)");
    if (f.kind == FaultKind::kSlip) {
      ModuleModel::SlipEvent e;
      e.t0 = start_time() + f.start;
      e.t1 = f.end ? start_time() + *f.end : std::numeric_limits<double>::infinity();
      e.ratio = f.ratio;
      modules_[f.target == "left-wheel" ? 0 : 1].slip_events.push_back(e);
    }
  }
}

double Simulation::data_duration() const {
  // The writer's sample count K: the last sample is stamped start + K / rate.
  const double K = std::floor((end_ - start_time()) * cfg_.rate_hz + 1e-6);
  return K / cfg_.rate_hz;
}

double Simulation::wheel_rate(int g, double t) const {
  if (!modules_[g].truth.wheel) return 0.0;
  return GroupStepper(*this, g, 0.0).rate_at(t).value();
}

double Simulation::slip_extra_angle(int g, const ModuleModel::SlipEvent& e) const {
  // alpha_dot - (fault-free alpha_dot) = ratio * w(t) * v_wc(t) / R (see wheel_rate_jet);
  // 4-point Gauss-Legendre over steps of one sample interval from t0 (w is C-infinity).
  const ModuleModel& m = modules_[g];
  const double h = 1.0 / cfg_.rate_hz, b_end = std::min(e.t1, end_);
  double sum = 0.0;
  for (double a = e.t0; a < b_end; a += h) {
    const double b = std::min(a + h, b_end);
    for (int i = 0; i < 4; ++i) {
      const double t = 0.5 * (a + b) + 0.5 * (b - a) * kGlX[i];
      JV p_o;
      JM C_v;
      scenario_->evaluate(t, p_o, C_v);
      sum += 0.5 * (b - a) * kGlW[i] * e.ratio * slip_window<kOrder>(t, e.t0, e.t1).value() *
             wheel_centre_speed_of(m, p_o, C_v) / m.radius;
    }
  }
  return sum;
}

ImuTruth Simulation::truth(int g, double t) const {
  GroupStepper st(*this, g, 0.0);
  const ModuleModel& m = modules_[g];
  double alpha = 0.0;
  if (m.truth.wheel) {
    const double t0 = start_time();
    const double h = 1.0 / cfg_.rate_hz;
    double a = t0;
    while (a < t) {
      const double b = std::min(t, a + h);
      for (int i = 0; i < 4; ++i)
        alpha += 0.5 * (b - a) * kGlW[i] * st.rate_at(0.5 * (a + b) + 0.5 * (b - a) * kGlX[i]).value();
      a = b;
    }
  }
  JV p_o, p;
  JM C_v, C_s;
  scenario_->evaluate(t, p_o, C_v);
  ImuTruth r;
  J alpha_jet(0.0);
  if (m.truth.wheel) {
    const J rate = wheel_rate_jet(m, t, p_o, C_v);
    alpha_jet = GroupStepper::integrate(alpha, rate);
    r.wheel_angle = alpha;
    r.wheel_rate = rate.value();
    r.wheel_centre_speed = wheel_centre_speed_of(m, p_o, C_v);
  }
  st.imu_jets(t, p_o, C_v, alpha_jet, p, C_s);
  r.p_inN = p.deriv(0);
  r.v_inN = p.deriv(1);
  r.a_inN = p.deriv(2);
  r.C_StoN = C_s.value();
  r.omega_nb_inS = body_rate(C_s);
  r.gyro_inS = r.omega_nb_inS + r.C_StoN.transpose() * omega_ie_;
  r.accel_inS = r.C_StoN.transpose() * (r.a_inN - Vec3(0, 0, gravity_) + 2.0 * omega_ie_.cross(r.v_inN));
  return r;
}

std::vector<ImuSample> Simulation::ideal_samples(int g, std::size_t count) const {
  GroupStepper st(*this, g, 0.0);
  std::vector<ImuSample> out;
  out.reserve(count);
  const double t0 = start_time();
  for (std::size_t k = 1; k <= count; ++k) {
    const double b = t0 + static_cast<double>(k) / cfg_.rate_hz;
    Vec3 gy, ac;
    st.step(b, gy, ac);
    ImuSample s;
    s.t = b;
    s.dt = 1.0 / cfg_.rate_hz;
    s.dtheta = gy * s.dt;
    s.dvel = ac * s.dt;
    out.push_back(s);
  }
  return out;
}

namespace {
ImuNoise datasheet_noise() {
  // What the manifest tells a filter to assume: the ICM20602-class datasheet figures.
  const ErrorParams d;
  ImuNoise n;
  n.gyro_arw = d.gyro_arw;
  n.acc_vrw = d.accel_vrw;
  n.gyro_bias_std = d.gyro_bias;
  n.acc_bias_std = d.accel_bias;
  n.gyro_sf_std = d.gyro_sf;
  n.acc_sf_std = d.accel_sf;
  n.gyro_bias_tau = n.acc_bias_tau = n.gyro_sf_tau = n.acc_sf_tau = 3600.0;
  return n;
}

/// One manifest module of group `group` with the given geometry and rolling radius
/// (the chip manifest states the calibrated geometry, the ideal manifest the truth) and the
/// gyro full scale (0: not stated).
ModuleSpec module_spec(const ModuleGeometry& geo, double radius, const std::string& name,
                       const std::string& group, const std::string& chip, const fs::path& file,
                       double rate_hz, double gyro_range) {
  ModuleSpec s;
  s.name = name;
  s.kind = geo.wheel ? ModuleKind::kWheel : ModuleKind::kBody;
  s.group = group;
  s.chip = chip;
  s.file = file;
  s.rate_hz = rate_hz;
  s.p_inV = geo.p_inV;
  s.lever_arm_inB = geo.wheel ? geo.lever_arm_inB : Vec3::Zero();
  s.mounting_rpy = geo.mounting_rpy;
  s.axle_sign = 1;
  s.wheel_radius = geo.wheel ? radius : 0.0;
  s.gyro_range = gyro_range;
  s.noise = datasheet_noise();
  return s;
}
}  // namespace

double Simulation::gyro_range() const {
  // The chips' gyro full scale, stated when the saturation effect clips at it. The ideal
  // manifest states it too: it is a property of the chips (their data saturate there), and a
  // filter run on the error-free streams then flags the same instants as on the chip data.
  return cfg_.on("saturation") ? cfg_.errors.gyro_range : 0.0;
}

Manifest Simulation::manifest() const {
  Manifest m = ideal_manifest();
  m.name = "wheelins simulate (" + cfg_.profile + ", seed " + std::to_string(cfg_.seed) + ")";
  m.modules.clear();
  for (int g = 0; g < kGroups; ++g) {
    const ModuleModel& mm = modules_[g];
    for (const ChipModel& ch : chips_[g]) {
      const std::string chip = ch.name.substr(ch.name.find('-') + 1);
      m.modules.push_back(module_spec(mm.manifest, mm.radius_manifest, ch.name, group_name(g), chip,
                                      fs::path(group_dir(g)) / ("tri_" + chip + "_imu.bin"),
                                      cfg_.rate_hz, gyro_range()));
    }
  }
  return m;
}

Manifest Simulation::ideal_manifest() const {
  Manifest m;
  m.name = "wheelins simulate: error-free streams, exact geometry";
  m.truth_file = "GINS.bin";
  m.odometer_file = "odo.bin";
  m.static_start = start_time();
  m.static_end = std::min(scenario_->static_end(), end_);
  const VehicleState s0 = scenario_->state(start_time());
  const earth::LocalFrame lf(scenario_->origin());
  m.origin = lf.geodetic_from_ned(s0.p_inN);
  m.initial_heading = s0.rpy().z();
  m.gravity = gravity_;
  m.earth_rotation = cfg_.earth_rotation;
  m.track_width = cfg_.vehicle.track;
  for (int g = 0; g < kGroups; ++g) {
    const ModuleModel& mm = modules_[g];
    m.modules.push_back(module_spec(
        mm.truth, mm.radius, std::string(g == 0 ? "left" : g == 1 ? "right" : "body") + "-ideal",
        group_name(g), "ideal", fs::path("ideal") / (std::string(group_name(g)) + "_imu.bin"),
        cfg_.rate_hz, gyro_range()));
  }
  return m;
}

std::string Simulation::errors_yaml() const {
  std::ostringstream o;
  const ErrorParams& e = cfg_.errors;
  o << "# wheelins simulate: every value drawn for this dataset (seed " << cfg_.seed << ", profile "
    << cfg_.profile << ").\n"
       "# Units in the key names. Only the enabled effects are listed; the white noise and\n"
       "# Gauss-Markov sequences are not stored, but each chip's total bias (turn-on + Gauss-Markov +\n"
       "# temperature) is in errors/<chip>_bias.bin at 1 Hz: t, gyro bias xyz [rad/s], accel bias xyz [m/s^2].\n";
  o << "seed: " << cfg_.seed << "\n";
  o << "effects: [";
  bool first = true;
  for (const auto& n : all_effects())
    if (cfg_.on(n)) {
      o << (first ? "" : ", ") << n;
      first = false;
    }
  o << "]\n";
  if (speed_scale_ != 1.0) o << "speed_profile_scale: " << num(speed_scale_) << "  # odometer speed scaled to the path length\n";
  o << "modules:\n";
  for (int g = 0; g < kGroups; ++g) {
    const ModuleModel& m = modules_[g];
    o << "  " << group_name(g) << ":\n";
    if (m.truth.wheel) {
      o << "    radius_true_m: " << num(m.radius) << "\n";
      o << "    radius_manifest_m: " << num(m.radius_manifest) << "\n";
      o << "    slip_per_m_s2: " << num(m.slip_coeff) << "\n";
    }
    o << "    time_offset_s: " << num(m.time_offset) << "  # a sample stamped t covers (t-dt+offset, t+offset]\n";
    if (!m.vibration.empty())
      o << "    vibration_cruise_speed_m_s: " << num(m.vib_cruise_speed) << "  # the vibration scales with speed\n";
    if (m.truth.wheel && cfg_.on("wheel_noise"))
      o << "    wheel_accel_noise_m_s_sqrt_h: " << num(e.wheel_accel_noise * 60.0)
        << "  # white, each accelerometer axis, at the cruise speed " << num(m.vib_cruise_speed)
        << " m/s; x " << num(e.wheel_accel_noise_rest) << " at rest, with the vibration gain between\n";
    o << "    temperature_rise_K: " << num(m.temp_rise) << "  # tau " << num(e.temp_tau) << " s\n";
    o << "    position_v_m: {true: " << vec(m.truth.p_inV) << ", manifest: " << vec(m.manifest.p_inV) << "}\n";
    if (m.truth.wheel)
      o << "    lever_arm_b_m: {true: " << vec(m.truth.lever_arm_inB) << ", manifest: " << vec(m.manifest.lever_arm_inB) << "}\n";
    o << "    mounting_deg: {true: " << vec(m.truth.mounting_rpy, kDeg) << ", manifest: " << vec(m.manifest.mounting_rpy, kDeg) << "}\n";
    if (!m.vibration.empty()) {
      o << "    vibration:  # per dof: [frequency_hz, amplitude (m or rad), phase_rad] of each sinusoid\n";
      static const char* names[6] = {"x_m", "y_m", "z_m", "roll_rad", "pitch_rad", "yaw_rad"};
      for (int d = 0; d < 6; ++d) {
        o << "      " << names[d] << ": [";
        for (std::size_t i = 0; i < m.vibration.dof[d].size(); ++i) {
          const auto& c = m.vibration.dof[d][i];
          o << (i ? ", " : "") << "[" << num(c.omega / (2 * kPi)) << ", " << num(c.amplitude) << ", " << num(c.phase) << "]";
        }
        o << "]\n";
      }
    }
    o << "    chips:\n";
    for (const ChipModel& c : chips_[g]) {
      o << "      " << c.name << ":\n";
      o << "        gyro_bias_deg_h: " << vec(c.gyro_bias, kDeg / 3600.0) << "\n";
      o << "        gyro_gm_initial_deg_h: " << vec(c.gyro_gm0, kDeg / 3600.0) << "\n";
      o << "        gyro_scale_factor_ppm: " << vec(c.gyro_T.diagonal() - Vec3::Ones(), 1e-6) << "\n";
      o << "        gyro_matrix: [" << vec(c.gyro_T.row(0).transpose()) << ", " << vec(c.gyro_T.row(1).transpose())
        << ", " << vec(c.gyro_T.row(2).transpose()) << "]  # I + scale factor + misalignment\n";
      o << "        gyro_tempco_deg_h_per_K: " << vec(c.gyro_tempco, kDeg / 3600.0) << "\n";
      o << "        accel_bias_m_s2: " << vec(c.accel_bias) << "\n";
      o << "        accel_gm_initial_m_s2: " << vec(c.accel_gm0) << "\n";
      o << "        accel_scale_factor_ppm: " << vec(c.accel_T.diagonal() - Vec3::Ones(), 1e-6) << "\n";
      o << "        accel_matrix: [" << vec(c.accel_T.row(0).transpose()) << ", " << vec(c.accel_T.row(1).transpose())
        << ", " << vec(c.accel_T.row(2).transpose()) << "]\n";
      o << "        accel_tempco_m_s2_per_K: " << vec(c.accel_tempco) << "\n";
    }
  }
  // Fault events: what each one did, with its interval as stamps (sensor faults act on the
  // stamped samples) or true times (slip acts on the motion).
  if (cfg_.faults.empty()) {
    o << "faults: []\n";
    return o.str();
  }
  o << "faults:  # times since the start of the data " << num(start_time())
    << " s; sensor faults act on the samples stamped in [start, end)\n";
  int slip_index[2] = {0, 0};
  for (const FaultEvent& f : cfg_.faults) {
    o << "  - spec: \"" << f.spec() << "\"\n";
    std::string chips;
    for (int g = 0; g < kGroups; ++g)
      for (const ChipModel& c : chips_[g])
        if (f.targets(group_name(g), c.name)) chips += (chips.empty() ? "" : ", ") + c.name;
    o << "    chips: [" << chips << "]\n";
    const std::string end = f.end ? num(start_time() + *f.end) : std::string("end");
    if (f.kind == FaultKind::kSlip) {
      const int g = f.target == "left-wheel" ? 0 : 1;
      const ModuleModel::SlipEvent& e = modules_[g].slip_events[slip_index[g]++];
      const double ramp = std::isfinite(e.t1) ? std::min(kSlipRamp, 0.5 * (e.t1 - e.t0)) : kSlipRamp;
      o << "    true_time_s: [" << num(e.t0) << ", " << end << "]  # also the error-free stream "
        << group_name(g) << "\n";
      o << "    ramp_s: " << num(ramp) << "  # C-infinity ramps inside the interval\n";
      o << "    extra_wheel_angle_rad: " << num(slip_extra_angle(g, e))
        << "  # integral of ratio * w(t) * v_wheel_centre / R within the data\n";
      continue;
    }
    o << "    stamps_s: [" << num(start_time() + f.start) << ", " << end << "]\n";
    if (f.kind == FaultKind::kGyroBiasJump || f.kind == FaultKind::kAccelBiasJump) {
      Vec3 step = Vec3::Zero();
      step[f.axis] = f.value_si();
      o << "    " << (f.gyro ? "gyro_bias_step_rad_s: " : "accel_bias_step_m_s2: ") << vec(step)
        << "  # added to the bias (and to errors/<chip>_bias.bin)\n";
    }
  }
  return o.str();
}

namespace {

/// The per-sample error model of one chip (state: Gauss-Markov biases and noise streams).
class ChipErrors {
 public:
  ChipErrors(const SimConfig& cfg, const ChipModel& m)
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
  /// Advances the processes by one sample and corrupts the true mean rates.
  /// `wheel_sigma`: the per-sample sigma of the wheel_noise effect now (0: none).
  /// `gyro_step` / `accel_step` (may be null): bias-jump faults added to the bias.
  void apply(double dT, const Vec3& w, const Vec3& f, Vec3& wm, Vec3& fm, double wheel_sigma,
             const Vec3* gyro_step = nullptr, const Vec3* accel_step = nullptr) {
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
  const Vec3& gyro_bias() const { return bg_; }
  const Vec3& accel_bias() const { return ba_; }

 private:
  const ErrorParams& e_;
  const ChipModel& m_;
  Rng gm_g_, gm_a_, arw_, vrw_, wheel_noise_;
  Vec3 bg_gm_, ba_gm_, bg_ = Vec3::Zero(), ba_ = Vec3::Zero();
  bool on_gm_g_, on_gm_a_, on_arw_, on_vrw_, on_sat_, on_q_;
  double phi_g_, q_g_, phi_a_, q_a_, s_arw_, s_vrw_;
};

/// The sensor-fault events of one chip, applied to its output samples in the writer.
class ChipFaults {
 public:
  ChipFaults(const std::vector<FaultEvent>& faults, const std::string& group, const std::string& chip) {
    for (const FaultEvent& f : faults) {
      if (!f.targets(group, chip)) continue;
      if (f.kind == FaultKind::kDropout) dropouts_.push_back(&f);
      if (f.kind == FaultKind::kGyroBiasJump || f.kind == FaultKind::kAccelBiasJump) jumps_.push_back(&f);
      if (f.kind == FaultKind::kStuck) stuck_.push_back({&f, 0.0, false});
    }
  }
  /// The bias steps active at `tau` (seconds since the start of the data); false if none.
  bool steps(double tau, Vec3& gyro, Vec3& accel) const {
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
  /// Stuck axes: during the event the axis repeats the last output before its start (the
  /// first output if the event starts before the first sample).
  void hold(double tau, Vec3& wm, Vec3& fm) {
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
  /// True if no sample is written at `tau`.
  bool dropped(double tau) const {
    for (const FaultEvent* f : dropouts_)
      if (f->active(tau)) return true;
    return false;
  }

 private:
  struct Stuck {
    const FaultEvent* f;
    double value;
    bool have;
  };
  std::vector<const FaultEvent*> dropouts_, jumps_;
  std::vector<Stuck> stuck_;
};

std::uint64_t file_bytes(const fs::path& p) {
  std::error_code ec;
  const auto n = fs::file_size(p, ec);
  return ec ? 0 : n;
}

void write_text_file(const fs::path& file, const std::string& text, bool overwrite) {
  AtomicTextFile f(file, overwrite);
  f.write(text);
  f.commit();
}

}  // namespace

DatasetSummary Simulation::write(const fs::path& dir, bool force, bool progress) const {
  const auto wall0 = std::chrono::steady_clock::now();
  std::error_code ec;
  if (fs::exists(dir, ec)) {
    if (!fs::is_directory(dir, ec)) throw InputError("'" + dir.string() + "': exists and is not a directory");
    if (!fs::is_empty(dir, ec) && !force)
      throw InputError("'" + dir.string() + "': directory is not empty (use --force to overwrite)");
  }
  fs::create_directories(dir, ec);
  if (ec) throw InputError("'" + dir.string() + "': cannot create: " + ec.message());
  for (int g = 0; g < kGroups; ++g) fs::create_directories(dir / group_dir(g));
  if (cfg_.write_ideal) fs::create_directories(dir / "ideal");
  fs::create_directories(dir / "errors");

  const double t0 = start_time();
  const double rate = cfg_.rate_hz;
  const std::uint64_t K = static_cast<std::uint64_t>(std::floor((end_ - t0) * rate + 1e-6));
  if (K < 2) throw InputError("simulate: the duration is shorter than two samples");
  auto stamp = [&](std::uint64_t k) { return t0 + static_cast<double>(k) / rate; };
  const std::uint64_t per_second = static_cast<std::uint64_t>(std::llround(rate));

  std::atomic<std::uint64_t> done{0};
  std::atomic<int> finished{0};
  std::exception_ptr errors[kGroups];
  auto worker = [&](int g) {
    try {
      const ModuleModel& m = modules_[g];
      const bool wheel_noise = m.truth.wheel && cfg_.on("wheel_noise");
      GroupStepper st(*this, g, m.time_offset);
      std::unique_ptr<GroupStepper> ideal;
      if (m.time_offset != 0.0) ideal = std::make_unique<GroupStepper>(*this, g, 0.0);
      std::unique_ptr<BinaryRowWriter> ideal_out;
      if (cfg_.write_ideal)
        ideal_out = std::make_unique<BinaryRowWriter>(
            dir / "ideal" / (std::string(group_name(g)) + "_imu.bin"), 7);
      std::vector<std::unique_ptr<BinaryRowWriter>> outs, bias_outs;
      std::vector<std::unique_ptr<ChipErrors>> errs;
      std::vector<ChipFaults> faults;
      for (const ChipModel& c : chips_[g]) {
        faults.emplace_back(cfg_.faults, group_name(g), c.name);
        const std::string chip = c.name.substr(c.name.find('-') + 1);
        outs.push_back(std::make_unique<BinaryRowWriter>(dir / group_dir(g) / ("tri_" + chip + "_imu.bin"), 7));
        bias_outs.push_back(std::make_unique<BinaryRowWriter>(dir / "errors" / (c.name + "_bias.bin"), 7));
        errs.push_back(std::make_unique<ChipErrors>(cfg_, c));
      }
      double row[7];
      for (std::uint64_t k = 1; k <= K; ++k) {
        const double b = stamp(k);
        Vec3 w, f, wi, fi;
        st.step(b, w, f);
        if (ideal) ideal->step(b, wi, fi);
        else wi = w, fi = f;
        row[0] = b;
        for (int i = 0; i < 3; ++i) row[1 + i] = wi[i], row[4 + i] = fi[i];
        if (ideal_out) ideal_out->write(row);
        const double dT = m.temp_rise * (1.0 - std::exp(-(b + m.time_offset - t0) / cfg_.errors.temp_tau));
        // Sample k is at tau = k / rate since the start of the data (fault times).
        const double tau = static_cast<double>(k) / rate;
        // Wheel white noise from rolling: its density follows the vibration gain of the speed.
        double wheel_sigma = 0.0;
        if (wheel_noise) {
          const double v = scenario_->state(b + m.time_offset - 0.5 / rate).v_inN.norm();
          const double rest = cfg_.errors.wheel_accel_noise_rest;
          wheel_sigma = cfg_.errors.wheel_accel_noise * std::sqrt(rate) *
                        (rest + (1.0 - rest) * vibration_gain(m, v));
        }
        for (std::size_t c = 0; c < errs.size(); ++c) {
          Vec3 wm, fm, step_g, step_a;
          // The error model runs on every sample (a dropout or a stuck axis draws the same
          // random numbers), so the data after a sensor fault equal the fault-free run's.
          if (faults[c].steps(tau, step_g, step_a))
            errs[c]->apply(dT, w, f, wm, fm, wheel_sigma, &step_g, &step_a);
          else
            errs[c]->apply(dT, w, f, wm, fm, wheel_sigma);
          faults[c].hold(tau, wm, fm);
          for (int i = 0; i < 3; ++i) row[1 + i] = wm[i], row[4 + i] = fm[i];
          if (!faults[c].dropped(tau)) outs[c]->write(row);
          if (k % per_second == 0) {
            const Vec3& bg = errs[c]->gyro_bias();
            const Vec3& ba = errs[c]->accel_bias();
            for (int i = 0; i < 3; ++i) row[1 + i] = bg[i], row[4 + i] = ba[i];
            bias_outs[c]->write(row);
          }
        }
        if ((k & 255) == 0) {
          done += 256;
          check_interrupt();  // Ctrl-C: stop here too, not only in the progress thread
        }
      }
      if (ideal_out) ideal_out->commit();
      for (auto& o : outs) o->commit();
      for (auto& o : bias_outs) o->commit();
    } catch (...) {
      errors[g] = std::current_exception();
    }
    ++finished;
  };
  std::vector<std::thread> threads;
  for (int g = 0; g < kGroups; ++g) threads.emplace_back(worker, g);

  // Truth (200 Hz) and odometer (2 Hz) in this thread.
  Progress prog("simulate", K * kGroups + K, progress);
  std::exception_ptr main_error;
  try {
    const earth::LocalFrame lf(scenario_->origin());
    TruthWriter truth(dir / "GINS.bin", force, cfg_.gps_week);
    BinaryRowWriter odo(dir / "odo.bin", 2);
    const std::uint64_t odo_every = std::max<std::uint64_t>(1, std::llround(rate * 0.5));  // 2 Hz
    for (std::uint64_t k = 0; k <= K; ++k) {
      const double t = stamp(k);
      const VehicleState s = scenario_->state(t);
      TruthRecord r;
      r.t = t;
      r.lla = lf.geodetic_from_ned(s.p_inN);
      r.v_ned = s.v_inN;
      r.rpy = s.rpy();
      truth.write(r);
      if (k > 0 && k % odo_every == 0) {
        const double row[2] = {t, s.forward_speed()};
        odo.write(row);
      }
      if ((k & 1023) == 0) prog.update(done + k);
    }
    truth.commit();
    odo.commit();
    while (finished < kGroups) {
      prog.update(done + K);
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
  } catch (...) {
    main_error = std::current_exception();
  }
  for (auto& th : threads) th.join();
  prog.finish();
  if (main_error) std::rethrow_exception(main_error);
  for (auto& e : errors)
    if (e) std::rethrow_exception(e);

  // Manifests and settings last: a dataset with a manifest is complete.
  write_text_file(dir / "errors.yaml", errors_yaml(), force);
  write_text_file(dir / "scenario.yaml", cfg_.to_yaml(), force);
  ManifestAnnotations notes;
  notes.header = {"simulated by wheelins simulate; settings in scenario.yaml, drawn errors in errors.yaml",
                  scenario_->describe()};
  if (cfg_.write_ideal) save_manifest(ideal_manifest(), dir / "manifest-ideal.yaml", notes);
  save_manifest(manifest(), dir / "manifest.yaml", notes);

  DatasetSummary sum;
  sum.duration = end_ - t0;
  sum.distance = scenario_->distance(end_);
  sum.imu_rows = K;
  sum.scenario = scenario_->describe();
  for (const auto& entry : fs::recursive_directory_iterator(dir)) {
    if (!entry.is_regular_file()) continue;
    sum.bytes += file_bytes(entry.path());
    ++sum.files;
  }
  sum.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  return sum;
}

}  // namespace wheelins::sim
