// Named IMU configurations (paper Table 1) resolved against a manifest's module
// groups: single (one Wheel-IMU), dual-wheel, body-wheel, triple; or an explicit
// module list.
#pragma once

#include <string>
#include <vector>

#include "wheelins/io/manifest.hpp"

namespace wheelins {

/// The configurations wheelins knows by name, in the paper's order.
const std::vector<std::string>& configuration_names();

/// Module names for `configuration` with one chip per IMU position (e.g. {"C1","C4"} for
/// dual-wheel: left C1, right C4). Positions: single = [left], dual-wheel = [left, right],
/// body-wheel = [left, body], triple = [left, right, body]. An empty chip list takes the
/// first chip of each group. Groups are found by kind and side: a wheel group whose
/// modules sit at negative v-frame y is "left". Throws InputError naming what is missing.
std::vector<std::string> configuration_modules(const Manifest& m, const std::string& configuration,
                                               const std::vector<std::string>& chips);

}  // namespace wheelins
