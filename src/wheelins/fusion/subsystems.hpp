// The navigator's subsystems (paper Section III), one per selected IMU: a Wheel-INS
// for every Wheel-IMU and a Body-INS for at most one Body-IMU, built from the
// VehicleSetup, with typed access to each kind, the fusion weights k_i of eq. (8),
// and where each one's samples come from (for messages).
#pragma once

#include <array>
#include <memory>
#include <string>
#include <vector>

#include "wheelins/fusion/options.hpp"

namespace wheelins {

class Subsystems {
 public:
  /// Throws InputError if a name is unknown, two Body-IMUs are selected, there is no
  /// Wheel-IMU, the weights do not fit, or more than kMaxModules modules are selected.
  Subsystems(const VehicleSetup& setup, const std::vector<std::string>& modules,
             const NavigatorOptions& options);
  Subsystems(const Subsystems&) = delete;
  Subsystems& operator=(const Subsystems&) = delete;

  int size() const { return static_cast<int>(subs_.size()); }
  Subsystem& operator[](int i) { return *subs_[i]; }
  const Subsystem& operator[](int i) const { return *subs_[i]; }
  Subsystem& at(int i) { return *subs_.at(i); }
  const Subsystem& at(int i) const { return *subs_.at(i); }

  bool is_wheel(int i) const { return wheel_[i] != nullptr; }
  /// Subsystem i as a Wheel-INS (is_wheel(i) must hold).
  const WheelIns& wheel(int i) const { return *wheel_[i]; }
  WheelIns& wheel(int i) { return *wheel_[i]; }
  bool has_body() const { return body_ != nullptr; }
  int body_index() const { return body_index_; }  ///< -1 without a Body-INS
  const BodyIns& body() const { return *body_; }

  /// k_i of eq. (8), normalised to a sum of 1 over all subsystems.
  double weight(int i) const { return weights_[i]; }
  /// Replaces the weights (each > 0, normalised here to a sum of 1).
  void set_weights(const std::array<double, kMaxModules>& k);
  /// Subsystem i is a steered wheel that follows: tied to the reference of eq. (8) but not in
  /// it, nor in the output, while a Wheel-IMU that does not steer counts (the configuration
  /// has one and FusionOptions::steered_in_reference is off; AidContext::reference_modules).
  bool follows(int i) const { return follows_[i]; }
  /// Where subsystem i's samples come from (e.g. its file).
  const std::string& source(int i) const { return sources_[i]; }

 private:
  std::vector<std::unique_ptr<Subsystem>> subs_;
  std::array<WheelIns*, kMaxModules> wheel_{};
  std::array<bool, kMaxModules> follows_{};
  BodyIns* body_ = nullptr;
  int body_index_ = -1;
  std::vector<double> weights_;
  std::vector<std::string> sources_;
};

}  // namespace wheelins
