// Building the navigator's subsystems from a VehicleSetup (subsystems.hpp), with the
// checks of the selection and the normalised weights.
#include "wheelins/fusion/subsystems.hpp"

#include <cmath>
#include <numeric>

namespace wheelins {

Subsystems::Subsystems(const VehicleSetup& setup, const std::vector<std::string>& modules,
                       const NavigatorOptions& opt) {
  if (modules.empty()) throw InputError("no module selected: name at least one Wheel-IMU");
  MechanizationOptions mech;
  mech.method = opt.mechanization;
  mech.gravity = setup.gravity;
  if (opt.earth_rotation) mech.omega_ie_inW = earth::earth_rate_ned(setup.origin.lat);
  std::vector<WheelIns*> wheels(modules.size(), nullptr);
  for (const auto& name : modules) {
    const ImuModule* m = setup.find(name);
    if (!m) {
      std::string known;
      for (const auto& mm : setup.modules) known += (known.empty() ? "" : ", ") + mm.name;
      throw InputError("'" + setup.source + "': no module named '" + name + "' (modules: " +
                       known + ")");
    }
    const std::size_t at = static_cast<std::size_t>(m - setup.modules.data());
    sources_.push_back(at < setup.data_sources.size() ? setup.data_sources[at] : m->name);
    if (m->kind == ModuleKind::kWheel) {
      auto w = std::make_unique<WheelIns>(*m, opt.wheel, mech);
      wheels[subs_.size()] = w.get();
      subs_.push_back(std::move(w));
    } else {
      if (body_)
        throw InputError("module '" + name + "': only one Body-IMU can share its attitude; '" +
                         body_->module().name + "' is already selected");
      auto b = std::make_unique<BodyIns>(*m, opt.body, mech);
      body_ = b.get();
      body_index_ = static_cast<int>(subs_.size());
      subs_.push_back(std::move(b));
    }
    subs_.back()->ekf().set_covariance_interval(opt.covariance_interval);
  }
  bool any_wheel = false;
  for (const WheelIns* w : wheels) any_wheel = any_wheel || w != nullptr;
  if (!any_wheel)
    throw InputError("no Wheel-IMU among the selected modules: at least one IMU must be on a "
                     "wheel to measure the wheel speed");
  weights_ = opt.fusion.weights;
  if (weights_.empty()) weights_.assign(subs_.size(), 1.0);
  if (weights_.size() != subs_.size())
    throw InputError("fusion weights: " + std::to_string(weights_.size()) + " given for " +
                     std::to_string(subs_.size()) + " modules");
  const double wsum = std::accumulate(weights_.begin(), weights_.end(), 0.0);
  for (double w : weights_)
    if (!(w > 0.0) || !std::isfinite(wsum))  // a zero weight leaves the mean undefined when the others drop out
      throw InputError("fusion weights must be > 0 and finite (leave a module out instead of weighting it 0)");
  for (double& w : weights_) w /= wsum;
  if (subs_.size() > static_cast<std::size_t>(kMaxModules))
    throw InputError(std::to_string(subs_.size()) + " modules selected; at most " +
                     std::to_string(kMaxModules) + " can be fused");
  for (int i = 0; i < size(); ++i) wheel_[i] = wheels[i];
  bool unsteered = false;
  for (int i = 0; i < size(); ++i) unsteered = unsteered || (is_wheel(i) && !wheel(i).steered());
  for (int i = 0; i < size(); ++i)
    follows_[i] = unsteered && !opt.fusion.steered_in_reference && is_wheel(i) && wheel(i).steered();
}

void Subsystems::set_weights(const std::array<double, kMaxModules>& k) {
  double sum = 0.0;
  for (int i = 0; i < size(); ++i) sum += k[i];
  for (int i = 0; i < size(); ++i) weights_[i] = k[i] / sum;
}

}  // namespace wheelins
