// The random draws of a simulated dataset (docs/simulator.md): each module's physical
// parameters (true rolling radius, clock offset, temperature rise, vibration, the
// calibration residuals the manifest states) and each chip's error parameters. Every
// draw comes from its own stream, named by the module or chip and the quantity
// (sim/rng.hpp), so switching an effect off leaves every other number unchanged.
#pragma once

#include "wheelins/sim/chip_errors.hpp"
#include "wheelins/sim/kinematics.hpp"

namespace wheelins::sim {

/// A module with geometry `geo`: the truth, the manifest's geometry, and the physical effects
/// enabled in `cfg`, drawn from the streams of module `drawn_as` ("left-wheel", ...: its own
/// group, or the one SimConfig::draws_from names); `cruise`: the scenario's cruise speed (the
/// vibration gain's reference) [m/s].
ModuleModel draw_module(const SimConfig& cfg, const std::string& drawn_as, const ModuleGeometry& geo,
                        double cruise);

/// Chip `name` ("left-C1", ...) with the error effects enabled in `cfg`, its parameters drawn
/// from the streams of chip `drawn_as` (default: its own name; another chip's name gives a
/// chip with that chip's errors, SimConfig::draws_from).
ChipModel draw_chip(const SimConfig& cfg, const std::string& name, const std::string& drawn_as = {});

}  // namespace wheelins::sim
