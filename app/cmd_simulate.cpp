// `wheelins simulate`: writes a simulated multi-IMU dataset (docs/simulator.md).
#include <yaml-cpp/yaml.h>

#include <cstdio>
#include <iostream>
#include <optional>
#include <string>
#include <vector>

#include "cli.hpp"
#include "wheelins/nav/types.hpp"
#include "wheelins/io/output_dir.hpp"
#include "wheelins/io/text_util.hpp"
#include "wheelins/io/yaml_reader.hpp"
#include "wheelins/sim/simulator.hpp"

namespace {

struct Options {
  std::string scenario = "default";
  std::string speed_file;
  std::string preset;
  std::string profile;
  std::optional<std::uint64_t> seed;
  std::optional<double> duration;
  std::string out;
  bool force = false;
  bool quiet = false;
  std::vector<std::string> disable, only, settings, faults;
  std::string config;
  std::optional<double> radius, track, rate, terrain, static_s, speed, wheel_noise, start_steering;
  std::optional<int> laps, chips;
  bool no_earth_rotation = false;
  bool no_ideal = false;
};

std::vector<std::string> split_commas(const std::vector<std::string>& in) {
  std::vector<std::string> out;
  for (const auto& s : in) {
    std::size_t pos = 0;
    while (pos <= s.size()) {
      const auto c = s.find(',', pos);
      const std::string part = s.substr(pos, c == std::string::npos ? std::string::npos : c - pos);
      if (!part.empty()) out.push_back(part);
      if (c == std::string::npos) break;
      pos = c + 1;
    }
  }
  return out;
}

int run(const Options& o) {
  using namespace wheelins;
  sim::SimConfig cfg;
  if (!o.config.empty()) {
    YAML::Node node;
    try {
      node = load_yaml_file(o.config, "simulator settings");
    } catch (const YAML::Exception& e) {
      throw InputError("'" + o.config + "': " + e.what());
    }
    cfg.apply_yaml(node, "'" + o.config + "'");
  }
  if (!o.preset.empty()) cfg.vehicle = sim::VehicleConfig::preset_named(o.preset);
  if (!o.profile.empty()) cfg.set_profile(o.profile);
  for (const auto& s : o.settings) cfg.apply_setting(s);
  if (o.config.empty() || o.scenario != "default") cfg.scenario = o.scenario;
  if (!o.speed_file.empty()) cfg.speed_file = o.speed_file;
  if (o.seed) cfg.seed = *o.seed;
  if (o.duration) cfg.duration = *o.duration;
  if (o.rate) cfg.apply_setting("rate_hz=" + std::to_string(*o.rate));
  if (o.chips) cfg.apply_setting("chips=" + std::to_string(*o.chips));
  if (o.laps) cfg.apply_setting("laps=" + std::to_string(*o.laps));
  if (o.radius) cfg.apply_setting("vehicle.wheel_radius_m=" + std::to_string(*o.radius));
  if (o.track) cfg.apply_setting("vehicle.track_m=" + std::to_string(*o.track));
  if (o.speed) cfg.speed = *o.speed;
  if (o.terrain) cfg.terrain_slope_deg = *o.terrain;
  if (o.start_steering) cfg.start_steering_deg = *o.start_steering;
  if (o.static_s) cfg.static_duration = *o.static_s;
  if (o.no_earth_rotation) cfg.earth_rotation = false;
  if (o.no_ideal) cfg.write_ideal = false;
  if (o.wheel_noise) {
    cfg.apply_setting("errors.wheel_accel_noise_m_s_sqrt_h=" + wheelins::io_detail::format_double(*o.wheel_noise));
    cfg.effects.insert("wheel_noise");
  }
  for (const auto& f : o.faults) cfg.faults.push_back(sim::parse_fault_spec(f));  // after --config's
  if (!o.only.empty()) cfg.only(split_commas(o.only));
  cfg.disable(split_commas(o.disable));

  cfg.validate();  // every setting in, so a message names the right option
  // The dataset appears whole or not at all: written into a staging directory that replaces
  // the target in one step (io/output_dir.hpp); --force replaces an earlier dataset as a
  // whole and never one that holds an input of this command.
  OutputDirOptions out_opt;
  out_opt.overwrite = o.force;
  out_opt.kind = "dataset";
  if (!o.config.empty()) out_opt.inputs.push_back(o.config);
  if (cfg.scenario != "default") out_opt.inputs.push_back(cfg.scenario);
  if (cfg.speed_file) out_opt.inputs.push_back(*cfg.speed_file);
  out_opt.notice = stderr_sink();
  OutputDir out(o.out, out_opt);
  const sim::Simulation simulation(cfg);
  const auto sum = simulation.write(out.staging(), false, !o.quiet);
  out.commit();
  if (!o.quiet) {
    std::printf("scenario  %s\n", sum.scenario.c_str());
    std::printf("profile   %s, seed %llu, effects:", cfg.profile.c_str(),
                static_cast<unsigned long long>(cfg.seed));
    for (const auto& e : sim::all_effects())
      if (cfg.on(e)) std::printf(" %s", e.c_str());
    if (cfg.effects.empty()) std::printf(" none");
    std::printf("\n");
    if (simulation.speed_scale() != 1.0)
      std::printf("speed     odometer speed scaled by %.5f to match the path length\n",
                  simulation.speed_scale());
    std::printf("duration  %.1f s (%llu samples at %g Hz), distance %.1f m\n", sum.duration,
                static_cast<unsigned long long>(sum.imu_rows), cfg.rate_hz, sum.distance);
    if (simulation.gyro_range() > 0.0)
      std::printf("gyro      full scale %g deg/s (saturation on)\n", simulation.gyro_range() / kDeg);
    std::printf("faults    %s\n", cfg.faults.empty() ? "none" : "(times in s since the start of the data)");
    for (const auto& f : cfg.faults) std::printf("          %s\n", f.spec().c_str());
    std::printf("output    %s: %d files, %.1f MB, written in %.1f s\n", o.out.c_str(), sum.files,
                sum.bytes / 1e6, sum.seconds);
  }
  return 0;
}

const bool registered = wheelins::cli::register_command(
    20, "simulate", "Simulate a multi-IMU (Wheel-IMUs + Body-IMU) dataset with exact kinematics",
    [](CLI::App& sub) {
      auto o = std::make_shared<Options>();
      sub.add_option("--scenario", o->scenario,
                     "default (T-shaped loop, 5 laps) or a path file: .kml (<LineString>) or .csv")
          ->capture_default_str();
      sub.add_option("--speed", o->speed_file, "odo.bin (t, speed) timing the path (with a path file)");
      sub.add_option("--preset", o->preset,
                     "vehicle preset: robot (default), car, or car-steered (the car with two more "
                     "Wheel-IMUs on its steered front wheels)");
      sub.add_option("--profile", o->profile, "error profile: field (default), datasheet or ideal");
      sub.add_option("--seed", o->seed, "random seed (default 1)");
      sub.add_option("--duration", o->duration, "seconds from the start (default: whole scenario)");
      sub.add_option("--out", o->out, "output dataset directory")->required();
      sub.add_flag("--force", o->force,
                   "replace an earlier dataset in --out as a whole (never a directory with other files)");
      sub.add_flag("--quiet,-q", o->quiet, "no progress and no summary");
      sub.add_option("--disable", o->disable, "switch effects off (comma list; see docs/simulator.md)");
      sub.add_option("--only", o->only, "switch only these effects on (comma list)");
      sub.add_option("--config", o->config, "settings YAML (the scenario.yaml format)");
      sub.add_option("--set", o->settings, "override one setting: key.path=value (repeatable)");
      sub.add_option("--radius", o->radius, "nominal wheel radius [m]");
      sub.add_option("--track", o->track, "track width [m]");
      sub.add_option("--rate", o->rate, "IMU rate [Hz] (default 200)");
      sub.add_option("--chips", o->chips, "chips per module (default 4)");
      sub.add_option("--laps", o->laps, "laps of the default scenario (default 5)");
      sub.add_option("--cruise-speed", o->speed, "cruise speed [m/s] (default scenario / path without odo)");
      sub.add_option("--terrain", o->terrain, "smooth terrain with slopes up to this many degrees (0: flat)");
      sub.add_option("--static", o->static_s, "static period at the start [s] (default 30)");
      sub.add_option("--start-steering-deg", o->start_steering,
                     "start at rest on an arc that turns the front axle's centre by this many degrees "
                     "(positive: right; curvature tan(D) / vehicle.wheelbase_m), then join the default "
                     "scenario's loop (default 0: no arc)");
      sub.add_option("--wheel-noise", o->wheel_noise,
                     "white noise on the Wheel-IMU accelerometers from rolling [m/s/sqrt(h)] at the "
                     "cruise speed (effect wheel_noise; none at rest unless errors.wheel_accel_noise_rest)");
      sub.add_flag("--no-earth-rotation", o->no_earth_rotation, "data without the earth rotation rate");
      sub.add_flag("--no-ideal", o->no_ideal,
                   "skip the error-free streams (ideal/, manifest-ideal.yaml): half the disk");
      sub.add_option("--fault", o->faults,
                     "sensor fault (repeatable): KIND:TARGET:T0[:T1|end][:key=value,...], times in s since "
                     "the start of the data (no T1 or 'end': until the end); KIND dropout | gyro-bias-jump "
                     "(axis=x|y|z,value=DEG_S) | accel-bias-jump (axis,value=M_S2) | stuck "
                     "(sensor=gyro|accel,axis) | slip (wheel groups; ratio=S: the wheel turns at (1+S) x its "
                     "rolling rate); TARGET a chip (left-C1) or a group (left-wheel, right-wheel, body)");
      sub.footer(
          "Fault examples (docs/simulator.md, \"Sensor faults\"):\n"
          "  --fault dropout:left-C1:300:360                          no left-C1 samples stamped in [300 s, 360 s)\n"
          "  --fault dropout:body:500                                 the Body-IMU chips stop at 500 s\n"
          "  --fault gyro-bias-jump:right-C1:400:end:axis=z,value=0.5 +0.5 deg/s on gyro z from 400 s on\n"
          "  --fault stuck:body-C1:200:260:sensor=gyro,axis=z         gyro z repeats its last value\n"
          "  --fault slip:left-wheel:150:155:ratio=0.5                the left wheel spins 50 % too fast\n"
          "  --fault slip:right-wheel:600:603:ratio=-1                the right wheel is locked\n"
          "Gyro saturation at robot speeds: --set errors.gyro_range_deg_s=500");
      return [o]() { return run(*o); };
    });

}  // namespace
