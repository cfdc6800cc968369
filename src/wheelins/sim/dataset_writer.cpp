// The dataset writer of a Simulation (members declared in simulator.hpp): the two
// manifests (chip data with the calibrated geometry, error-free streams with the
// truth), errors.yaml (every value drawn), and write(): one thread per module steps
// its chips through the sample grid and writes their files, while this thread writes
// the truth and the odometer; the manifests come last, so a dataset with a manifest
// is complete.
#include "wheelins/sim/simulator.hpp"

#include <atomic>
#include <chrono>
#include <cmath>
#include <exception>
#include <sstream>
#include <thread>

#include "wheelins/io/atomic_file.hpp"
#include "wheelins/io/binary.hpp"
#include "wheelins/io/truth.hpp"
#include "wheelins/nav/types.hpp"
#include "wheelins/sim/faults.hpp"
#include "wheelins/sim/sampler.hpp"
#include "wheelins/sim/text.hpp"
#include "wheelins/util/interrupt.hpp"
#include "wheelins/util/progress.hpp"

namespace wheelins::sim {
namespace fs = std::filesystem;

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
  s.steered = geo.wheel && geo.steered;
  s.gyro_range = gyro_range;
  s.noise = datasheet_noise();
  return s;
}
}  // namespace

Manifest Simulation::manifest() const {
  Manifest m = ideal_manifest();
  m.name = "wheelins simulate (" + cfg_.profile + ", seed " + std::to_string(cfg_.seed) + ")";
  m.modules.clear();
  for (int g = 0; g < groups(); ++g) {
    const ModuleModel& mm = modules_[g];
    for (const ChipModel& ch : chips_[g]) {
      const std::string chip = ch.name.substr(ch.name.rfind('-') + 1);
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
  m.wheelbase = cfg_.vehicle.wheelbase;
  for (int g = 0; g < groups(); ++g) {
    const ModuleModel& mm = modules_[g];
    m.modules.push_back(module_spec(
        mm.truth, mm.radius, std::string(chip_prefix(g)) + "-ideal",
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
  for (int g = 0; g < groups(); ++g) {
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
  std::vector<std::size_t> slip_index(modules_.size(), 0);
  for (const FaultEvent& f : cfg_.faults) {
    o << "  - spec: \"" << f.spec() << "\"\n";
    std::string chips;
    for (int g = 0; g < groups(); ++g)
      for (const ChipModel& c : chips_[g])
        if (f.targets(group_name(g), c.name)) chips += (chips.empty() ? "" : ", ") + c.name;
    o << "    chips: [" << chips << "]\n";
    const std::string end = f.end ? num(start_time() + *f.end) : std::string("end");
    if (f.kind == FaultKind::kSlip) {
      const int g = group_index(f.target);
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
  for (int g = 0; g < groups(); ++g) fs::create_directories(dir / group_dir(g));
  if (cfg_.write_ideal) fs::create_directories(dir / "ideal");
  fs::create_directories(dir / "errors");

  const double t0 = start_time();
  const double rate = cfg_.rate_hz;
  const std::uint64_t K = sample_count();
  if (K < 2) throw InputError("simulate: the duration is shorter than two samples");
  auto stamp = [&](std::uint64_t k) { return this->stamp(k); };
  const std::uint64_t per_second = static_cast<std::uint64_t>(std::llround(rate));

  std::atomic<std::uint64_t> done{0};
  std::atomic<int> finished{0};
  std::exception_ptr errors[kMaxGroups];
  auto worker = [&](int g) {
    try {
      const ModuleModel& m = modules_[g];
      ModuleSampler sampler(*this, g);
      std::unique_ptr<GroupStepper> ideal;
      if (m.time_offset != 0.0) ideal = std::make_unique<GroupStepper>(*scenario_, m, clock(), 0.0);
      std::unique_ptr<BinaryRowWriter> ideal_out;
      if (cfg_.write_ideal)
        ideal_out = std::make_unique<BinaryRowWriter>(
            dir / "ideal" / (std::string(group_name(g)) + "_imu.bin"), 7);
      std::vector<std::unique_ptr<BinaryRowWriter>> outs, bias_outs;
      std::vector<ChipSampler> chips;
      for (const ChipModel& c : chips_[g]) {
        chips.emplace_back(*this, g, c);
        const std::string chip = c.name.substr(c.name.rfind('-') + 1);
        outs.push_back(std::make_unique<BinaryRowWriter>(dir / group_dir(g) / ("tri_" + chip + "_imu.bin"), 7));
        bias_outs.push_back(std::make_unique<BinaryRowWriter>(dir / "errors" / (c.name + "_bias.bin"), 7));
      }
      double row[7];
      for (std::uint64_t k = 1; k <= K; ++k) {
        sampler.step(k);
        const double b = sampler.t();
        Vec3 wi = sampler.gyro(), fi = sampler.accel();
        if (ideal) ideal->step(b, wi, fi);  // the error-free stream has no clock offset
        row[0] = b;
        for (int i = 0; i < 3; ++i) row[1 + i] = wi[i], row[4 + i] = fi[i];
        if (ideal_out) ideal_out->write(row);
        for (std::size_t c = 0; c < chips.size(); ++c) {
          Vec3 wm, fm;
          const bool kept = chips[c].read(sampler, wm, fm);
          for (int i = 0; i < 3; ++i) row[1 + i] = wm[i], row[4 + i] = fm[i];
          if (kept) outs[c]->write(row);
          if (k % per_second == 0) {
            const Vec3& bg = chips[c].errors().gyro_bias();
            const Vec3& ba = chips[c].errors().accel_bias();
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
  for (int g = 0; g < groups(); ++g) threads.emplace_back(worker, g);

  // Truth (200 Hz) and odometer (2 Hz) in this thread.
  Progress prog("simulate", K * static_cast<std::uint64_t>(groups()) + K, progress);
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
    while (finished < groups()) {
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
