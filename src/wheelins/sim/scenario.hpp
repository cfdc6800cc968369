// Vehicle motion for the simulator (GTSAM-style Scenario: pose and its
// derivatives at any time, exactly).
//
// The motion is that of the v-frame: origin o at the mid rear axle (axle
// height), x forward, y right, z down, in the n/w-frame (local NED at the
// origin, flat earth). Every quantity comes from one analytic, C-infinity
// description evaluated with Taylor jets (sim/jet.hpp): no finite differences.
#pragma once

#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "wheelins/nav/earth.hpp"
#include "wheelins/sim/gauss_polyline.hpp"
#include "wheelins/sim/jet.hpp"

namespace wheelins::sim {

/// Jet order used for the vehicle motion: position to the 3rd derivative, so a
/// point on a wheel spinning with slip still has an exact acceleration.
constexpr int kOrder = 3;
using J = Jet<kOrder>;
using JV = JVec3<kOrder>;
using JM = JMat3<kOrder>;

/// The reference point o and the v-frame at one instant.
struct VehicleState {
  double t = 0.0;
  Vec3 p_inN = Vec3::Zero();      ///< position of o [m]
  Vec3 v_inN = Vec3::Zero();      ///< velocity of o [m/s]
  Vec3 a_inN = Vec3::Zero();      ///< acceleration of o [m/s^2]
  Mat3 C_VtoN = Mat3::Identity();  ///< C_v^n
  Vec3 omega_inV = Vec3::Zero();     ///< angular rate of v w.r.t. n, in v [rad/s]
  Vec3 omega_dot_inV = Vec3::Zero();  ///< its time derivative [rad/s^2]
  Vec3 rpy() const { return euler_from_dcm(C_VtoN); }
  /// Forward speed of o (v-frame x component of its velocity).
  double forward_speed() const { return C_VtoN.col(0).dot(v_inN); }
};

class Scenario {
 public:
  virtual ~Scenario() = default;
  virtual double start_time() const = 0;   ///< GPS seconds of week
  virtual double end_time() const = 0;
  /// The vehicle is at rest (to < 1e-6 m/s) on [start_time, static_end].
  virtual double static_end() const = 0;
  virtual earth::Geodetic origin() const = 0;
  /// Position of o (n-frame) and C_v^n as jets at time t.
  virtual void evaluate(double t, JV& p_inN, JM& C_VtoN) const = 0;
  /// The signed horizontal curvature of the path of o at time t as a jet in t [1/m]
  /// (positive: turning right, the n-frame being NED). It is a function of the position
  /// along the path, so it is defined at rest too (a steered wheel keeps its angle when the
  /// vehicle stops). Zero unless the scenario has a path.
  virtual J path_curvature(double t) const { (void)t; return J(0.0); }
  virtual std::string describe() const = 0;

  VehicleState state(double t) const;
  /// Distance travelled by o between start_time and t (Gauss-Legendre over 0.5 s steps).
  double distance(double t) const;
};

/// A flat-or-terrain path following scenario: a Gaussian-smoothed polyline in
/// north/east, driven along its (polyline) arc length u(t) given by a Gaussian-
/// smoothed integrated speed profile, with optional lateral skid and terrain.
struct Terrain {
  /// Height field H(n, e) = sum_i A_i sin(kn_i n + ke_i e + phase_i) [m, up].
  struct Wave {
    double amplitude = 0.0, kn = 0.0, ke = 0.0, phase = 0.0;
  };
  std::vector<Wave> waves;
  bool enabled() const { return !waves.empty(); }
  /// A field of three waves with slopes up to ~max_slope_deg, from a seed.
  static Terrain gentle(double max_slope_deg, std::uint64_t seed);
};

struct PathScenarioSpec {
  std::string name;
  earth::Geodetic origin;
  double start_time = 100000.0;
  std::vector<std::array<double, 2>> path_ne;  ///< polyline vertices, local north/east [m]
  double path_sigma = 2.0;                     ///< corner rounding (Gaussian sigma) [m]
  /// The integrated-speed profile: times and arc lengths (piecewise linear, increasing u).
  std::vector<double> profile_t, profile_u;
  double profile_sigma = 1.0;  ///< smoothing of the speed profile [s]
  double end_time = 0.0;
  double static_end = 0.0;
  /// Lateral skid: the velocity of o points outward of the turn by
  /// v_y = -skid_coeff * a_lat (a_lat = speed^2 * curvature). [s]
  double skid_coeff = 0.0;
  /// ... and by the slip angle skid_angle * a_lat (a tyre's law) [rad/(m/s^2)].
  double skid_angle = 0.0;
  Terrain terrain;
};

class PathScenario : public Scenario {
 public:
  explicit PathScenario(PathScenarioSpec spec);
  double start_time() const override { return spec_.start_time; }
  double end_time() const override { return spec_.end_time; }
  double static_end() const override { return spec_.static_end; }
  earth::Geodetic origin() const override { return spec_.origin; }
  void evaluate(double t, JV& p_inN, JM& C_VtoN) const override;
  J path_curvature(double t) const override;
  std::string describe() const override;
  const PathScenarioSpec& spec() const { return spec_; }
  /// The curvature of the smoothed path at arc length u (the derivatives of p~(u)) [1/m].
  double curvature_at(double u) const;
  /// Arc length parameter u(t) and its derivatives as a jet.
  J arc(double t) const;
  double polyline_length() const;

 private:
  PathScenarioSpec spec_;
  GaussPolyline<2> path_;
  GaussPolyline<1> profile_;
};

/// Options for the default scenario (the paper's field test: a T-shaped loop).
struct DefaultScenarioOptions {
  earth::Geodetic origin{30.5285 * kDeg, 114.3573 * kDeg, 25.0};  // Wuhan University
  double start_time = 100000.0;
  double static_duration = 30.0;  ///< at the start [s]
  int laps = 5;
  double speed = 1.4;        ///< cruise speed along the polyline [m/s]
  double path_sigma = 2.0;   ///< corner rounding [m] (turn radius ~1.8 m)
  double profile_sigma = 1.2;  ///< speed smoothing [s] (peak acceleration ~0.47 m/s^2)
  bool stops = true;         ///< stop for ~8 s after laps 2 and 4
  double stop_duration = 15.0;  ///< [s] each stop, of which about 7 s (6 speed sigmas) slowing and starting
  double rotation_deg = 25.0;  ///< heading of the T's stem
  double scale = 1.0;          ///< size of the T (1: 254 m per lap)
  double skid_coeff = 0.0;
  double skid_angle = 0.0;  ///< PathScenarioSpec::skid_angle
  Terrain terrain;
  /// A start with the wheels turned [1/m] (0: none): o starts at rest on an arc whose
  /// smoothed path has exactly this curvature at the start (positive: turning right), drives
  /// along it (a quarter turn, at most max(20 m, 3 path sigmas), at least 5 m of driving + 2 sigmas) and
  /// joins the T where the lap starts, along its first side.
  double start_curvature = 0.0;
};
PathScenarioSpec default_scenario_spec(const DefaultScenarioOptions& opt);

/// Options for a scenario from a real path.
struct PathFileOptions {
  std::optional<std::filesystem::path> speed_file;  ///< odo.bin (t, speed), optional
  double static_duration = 30.0;  ///< before the speed starts [s]
  double static_after = 10.0;     ///< after it ends [s]
  double speed = 1.4;             ///< constant cruise speed without a speed file [m/s]
  double start_time = 100000.0;   ///< without a speed file
  double path_sigma = 0.7;        ///< corner rounding [m]
  double profile_sigma = 0.5;     ///< speed smoothing [s]
  double min_spacing = 0.1;       ///< vertices closer than this to the last kept one are dropped [m]
  bool fit_speed_to_path = true;  ///< scale the integrated speed to the polyline length
  std::optional<earth::Geodetic> origin;  ///< default: the first path point (height from file or 0)
  double skid_coeff = 0.0;
  double skid_angle = 0.0;  ///< PathScenarioSpec::skid_angle
  Terrain terrain;
};
/// Reads a KML (<LineString> lon,lat[,h]) or CSV (lat,lon[,h] in degrees, or north,east
/// in metres with a header naming them) path and an optional odo.bin speed profile.
/// Throws InputError naming the file and the record on bad input.
PathScenarioSpec path_file_scenario_spec(const std::filesystem::path& path_file,
                                         const PathFileOptions& opt, double* speed_scale = nullptr);

/// Reads odo.bin: rows of (t, forward speed); strictly increasing t, finite values.
struct SpeedSamples {
  std::vector<double> t, v;
};
SpeedSamples read_speed_file(const std::filesystem::path& file);

}  // namespace wheelins::sim
