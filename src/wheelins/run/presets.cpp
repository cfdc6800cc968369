// The named IMU configurations of presets.hpp resolved against a manifest.
#include "wheelins/run/presets.hpp"

#include <algorithm>
#include <cmath>

#include "wheelins/nav/types.hpp"

namespace wheelins {

const std::vector<std::string>& configuration_names() {
  static const std::vector<std::string> names{"single", "dual-wheel", "body-wheel", "triple"};
  return names;
}

namespace {
enum class Slot { kLeft, kRight, kBody };

const char* slot_name(Slot s) {
  return s == Slot::kLeft ? "left wheel" : s == Slot::kRight ? "right wheel" : "body";
}

bool in_slot(const ModuleSpec& m, Slot s) {
  switch (s) {
    case Slot::kLeft: return m.kind == ModuleKind::kWheel && m.p_inV.y() < 0.0;
    case Slot::kRight: return m.kind == ModuleKind::kWheel && m.p_inV.y() >= 0.0;
    default: return m.kind == ModuleKind::kBody;
  }
}
}  // namespace

std::vector<std::string> configuration_modules(const Manifest& m, const std::string& name,
                                               const std::vector<std::string>& chips) {
  std::vector<Slot> slots;
  if (name == "single") slots = {Slot::kLeft};
  else if (name == "single-right") slots = {Slot::kRight};
  else if (name == "dual-wheel") slots = {Slot::kLeft, Slot::kRight};
  else if (name == "body-wheel") slots = {Slot::kLeft, Slot::kBody};
  else if (name == "triple") slots = {Slot::kLeft, Slot::kRight, Slot::kBody};
  else {
    std::string list;
    for (const auto& n : configuration_names()) list += (list.empty() ? "" : ", ") + n;
    throw InputError("unknown configuration '" + name + "' (known: " + list + ", single-right)");
  }
  if (!chips.empty() && chips.size() != slots.size())
    throw InputError("configuration '" + name + "' takes " + std::to_string(slots.size()) +
                     " chips (one per IMU), " + std::to_string(chips.size()) + " given");
  std::vector<std::string> out;
  for (std::size_t i = 0; i < slots.size(); ++i) {
    // Of several candidates, the wheel nearest the rear axle (x = 0: an unsteered wheel of a
    // car whose front wheels steer), the first listed among equals.
    const ModuleSpec* pick = nullptr;
    for (const auto& mod : m.modules) {
      if (!in_slot(mod, slots[i])) continue;
      if (chips.empty() || mod.chip == chips[i] || mod.name == chips[i])
        if (!pick || std::abs(mod.p_inV.x()) < std::abs(pick->p_inV.x())) pick = &mod;
    }
    // A lone Wheel-IMU (a manifest with no left one, e.g. the public single-IMU layout with
    // its wheel on the right) serves as the configuration's wheel when there is no right slot.
    if (!pick && chips.empty() && slots[i] == Slot::kLeft &&
        std::find(slots.begin(), slots.end(), Slot::kRight) == slots.end())
      for (const auto& mod : m.modules)
        if (mod.kind == ModuleKind::kWheel) {
          pick = &mod;
          break;
        }
    if (!pick)
      throw InputError("'" + m.path.string() + "': configuration '" + name + "' needs a " +
                       slot_name(slots[i]) + " IMU" +
                       (chips.empty() ? std::string() : " with chip '" + chips[i] + "'") +
                       ", and the manifest has none");
    out.push_back(pick->name);
  }
  return out;
}

}  // namespace wheelins
