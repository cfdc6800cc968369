// The facade of simulator.hpp: building the scenario, drawing every parameter, checking
// the fault events, and the accessors (truth_queries.cpp and dataset_writer.cpp hold the rest).
#include "wheelins/sim/simulator.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "wheelins/nav/types.hpp"
#include "wheelins/sim/draws.hpp"
#include "wheelins/sim/faults.hpp"
#include "wheelins/sim/text.hpp"

namespace wheelins::sim {

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
  static const char* n[kMaxGroups] = {"left-wheel", "right-wheel", "body", "front-left-wheel",
                                      "front-right-wheel"};
  return n[g];
}
const char* Simulation::group_dir(int g) {
  static const char* n[kMaxGroups] = {"left-wheel-imu", "right-wheel-imu", "body-imu",
                                      "front-left-wheel-imu", "front-right-wheel-imu"};
  return n[g];
}
const char* Simulation::chip_prefix(int g) {
  static const char* n[kMaxGroups] = {"left", "right", "body", "front-left", "front-right"};
  return n[g];
}

int Simulation::group_index(const std::string& name) const {
  for (int g = 0; g < groups(); ++g)
    if (name == group_name(g)) return g;
  return -1;
}

Simulation::Simulation(const SimConfig& cfg) : cfg_(cfg) {
  cfg_.validate();
  const bool car = cfg_.vehicle.car();
  Terrain terrain;
  if (cfg_.terrain_slope_deg > 0.0) terrain = Terrain::gentle(cfg_.terrain_slope_deg, cfg_.seed);
  const double skid = cfg_.on("skid") ? cfg_.errors.skid_coeff : 0.0;
  const double skid_angle = cfg_.on("skid") ? cfg_.errors.skid_angle : 0.0;
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
    o.stop_duration = cfg_.stop_s;
    o.skid_coeff = skid;
    o.skid_angle = skid_angle;
    o.terrain = terrain;
    // The front axle's centre (wheelbase, 0) turned by D: kappa = tan(D) / wheelbase.
    if (cfg_.start_steering_deg != 0.0)
      o.start_curvature = std::tan(cfg_.start_steering_deg * kDeg) / cfg_.vehicle.wheelbase;
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
    o.skid_angle = skid_angle;
    o.terrain = terrain;
    scenario_ = std::make_unique<PathScenario>(path_file_scenario_spec(cfg_.scenario, o, &speed_scale_));
  }
  const double cruise = cruise_speed_of(*scenario_);
  end_ = scenario_->end_time();
  if (cfg_.duration) end_ = std::min(end_, scenario_->start_time() + *cfg_.duration);
  const earth::Geodetic org = scenario_->origin();
  gravity_ = earth::normal_gravity(org.lat, org.h);
  omega_ie_ = cfg_.earth_rotation ? earth::earth_rate_ned(org.lat) : Vec3::Zero();

  // Modules: true geometry, manifest geometry, per-module physical draws; then the chips.
  // Every draw has its own stream named by the module or chip: the front wheels' draws leave
  // those of the other modules unchanged.
  const std::vector<const ModuleGeometry*> geo = cfg_.vehicle.modules();
  if (geo.size() > static_cast<std::size_t>(kMaxGroups)) throw InputError("simulate: too many modules");
  modules_.resize(geo.size());
  chips_.resize(geo.size());
  for (int g = 0; g < groups(); ++g) {
    if (geo[g]->group != group_name(g))
      throw InputError(std::string("simulate: module ") + std::to_string(g) + " is '" + geo[g]->group +
                       "', expected '" + group_name(g) + "'");
    const auto copy = cfg_.draws_from.find(group_name(g));
    const int drawn_as = copy == cfg_.draws_from.end() ? g : group_index(copy->second);  // validated
    modules_[g] = draw_module(cfg_, group_name(drawn_as), *geo[g], cruise);
    for (int c = 1; c <= cfg_.chips; ++c) {
      const std::string n = "-C" + std::to_string(c);
      chips_[g].push_back(draw_chip(cfg_, chip_prefix(g) + n, chip_prefix(drawn_as) + n));
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
    bool exists = false;  // the front wheels' targets need the preset that has them
    for (int g = 0; g < groups(); ++g)
      for (const ChipModel& c : chips_[g]) exists = exists || f.targets(group_name(g), c.name);
    if (!exists)
      throw InputError(what + "the vehicle (preset " + cfg_.vehicle.preset + ") has no module " + f.target);
    if (!(f.start < span))
      throw InputError(what + "the start " + num(f.start) + " s is outside the data (0 to " + num(span) +
                       " s since the start of the data)");
    if (f.kind == FaultKind::kSlip) {
      ModuleModel::SlipEvent e;
      e.t0 = start_time() + f.start;
      e.t1 = f.end ? start_time() + *f.end : std::numeric_limits<double>::infinity();
      e.ratio = f.ratio;
      modules_[group_index(f.target)].slip_events.push_back(e);
    }
  }
}

std::uint64_t Simulation::sample_count() const {
  return static_cast<std::uint64_t>(std::floor((end_ - start_time()) * cfg_.rate_hz + 1e-6));
}

double Simulation::data_duration() const {
  // The writer's sample count K: the last sample is stamped start + K / rate.
  const double K = std::floor((end_ - start_time()) * cfg_.rate_hz + 1e-6);
  return K / cfg_.rate_hz;
}

double Simulation::gyro_range() const {
  // The chips' gyro full scale, stated when the saturation effect clips at it. The ideal
  // manifest states it too: it is a property of the chips (their data saturate there), and a
  // filter run on the error-free streams then flags the same instants as on the chip data.
  return cfg_.on("saturation") ? cfg_.errors.gyro_range : 0.0;
}

StepperClock Simulation::clock() const {
  StepperClock c;
  c.rate_hz = cfg_.rate_hz;
  c.start_time = start_time();
  c.gravity = gravity_;
  c.omega_ie = omega_ie_;
  return c;
}

GroupStepper Simulation::stepper(int g, double offset) const {
  return GroupStepper(*scenario_, modules_[g], clock(), offset);
}

}  // namespace wheelins::sim
