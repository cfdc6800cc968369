// The random draws of a simulated dataset (docs/simulator.md): each module's physical
// parameters (true rolling radius, clock offset, temperature rise, vibration, the
// calibration residuals the manifest states) and each chip's error parameters. Every
// draw comes from its own stream, named by the module or chip and the quantity
// (sim/rng.hpp), so switching an effect off leaves every other number unchanged.
#pragma once

#include "wheelins/sim/chip_errors.hpp"
#include "wheelins/sim/kinematics.hpp"

namespace wheelins::sim {

/// Module `group` ("left-wheel", ...) with the given geometry: the truth, the manifest's
/// geometry, and the physical effects enabled in `cfg`; `cruise`: the scenario's cruise
/// speed (the vibration gain's reference) [m/s].
ModuleModel draw_module(const SimConfig& cfg, const std::string& group, const ModuleGeometry& geo,
                        double cruise);

/// Chip `name` ("left-C1", ...) with the error effects enabled in `cfg`.
ChipModel draw_chip(const SimConfig& cfg, const std::string& name);

}  // namespace wheelins::sim
