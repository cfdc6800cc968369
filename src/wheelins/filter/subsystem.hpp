// What the fusion needs from one IMU's navigation subsystem (Wheel-INS or
// Body-INS): each keeps its own strapdown EKF and exposes the vehicle quantities
// it implies (heading, reference point) with their measurement models.
#pragma once

#include "wheelins/filter/alignment.hpp"
#include "wheelins/filter/position_constraint.hpp"
#include "wheelins/filter/strapdown_ekf.hpp"
#include "wheelins/io/manifest.hpp"

namespace wheelins {

class Subsystem {
 public:
  Subsystem(const ModuleSpec& module, const MechanizationOptions& mech)
      : module_(module), mech_(mech) {}
  virtual ~Subsystem() = default;
  Subsystem(const Subsystem&) = delete;
  Subsystem& operator=(const Subsystem&) = delete;

  bool is_wheel() const { return module_.kind == ModuleKind::kWheel; }
  const ModuleSpec& module() const { return module_; }
  StrapdownEkf& ekf() { return ekf_; }
  const StrapdownEkf& ekf() const { return ekf_; }
  double time() const { return ekf_.state().t; }

  /// Rotates a raw sample from the sensor axes into the subsystem's b-frame.
  virtual ImuSample to_body(const ImuSample& sensor) const = 0;
  /// Aligns from the static mean and starts with o at the w-frame origin.
  virtual void start(const StaticAccumulator& stat, double vehicle_heading, double t0) = 0;
  /// One IMU epoch of b-frame data.
  virtual void propagate(const ImuSample& body_sample) { ekf_.propagate(body_sample); }
  virtual double vehicle_heading() const = 0;
  /// d(heading)/d(phi), for the heading's 1-sigma.
  virtual Eigen::RowVector3d heading_sensitivity() const = 0;
  /// Inputs of eq. (8) for this subsystem: where it puts the reference point o.
  virtual ReferencePointInput reference_point_input() const = 0;
  /// Vehicle velocity at o in the w-frame.
  virtual Vec3 reference_velocity_inW() const = 0;

  Vec3 reference_point_inW() const { return reference_point_model(reference_point_input()).r_o; }

 protected:
  ModuleSpec module_;
  MechanizationOptions mech_;
  StrapdownEkf ekf_;
};

}  // namespace wheelins
