// The vibration of a module (docs/simulator.md): band-limited sums of sinusoids in
// the displacement and the small rotation of the module, drawn once per module, so
// that the accelerations and rates they cause are exact derivatives; evaluated at
// the four quadrature nodes of a sample with one sine and cosine per component.
#pragma once

#include <array>
#include <vector>

#include "wheelins/sim/rng.hpp"
#include "wheelins/sim/scenario.hpp"

namespace wheelins::sim {

/// Band-limited vibration of a module: displacement (v-frame) and small rotation
/// (ZYX Euler angles, v-frame), each a sum of sinusoids with random frequencies in a
/// band, so its derivatives (the accelerations and rates it causes) are exact.
struct Vibration {
  struct Component {
    double amplitude = 0.0, omega = 0.0, phase = 0.0;
  };
  std::array<std::vector<Component>, 6> dof;  ///< x, y, z [m], roll, pitch, yaw [rad]
  std::array<std::vector<std::array<double, 8>>, 6> node_phasors;  ///< cos, sin of omega*offset_i
  std::array<std::vector<std::array<double, 4>>, 6> phase_state;   ///< sin, cos now; cos, sin of omega h
  double step_h = 0.0, last_mid = 0.0;
  int since_exact = -1;
  bool empty() const { return dof[0].empty(); }
  void eval(double t, JV& disp, JV& rot) const;
  /// The same at t_mid + offsets[i], i = 0..3, for offsets fixed by prepare() (one sine and
  /// cosine per component instead of four: the angle-sum identities do the rest).
  /// Consecutive calls h apart advance each component's phase by a rotation (recomputed
  /// exactly every 256 calls; the recurrence adds < 1e-13 relative error).
  void prepare(const double offsets[4], double h);
  void eval4(double t_mid, JV disp[4], JV rot[4]);
  static Vibration draw(Rng& rng, const Vec3& accel_rms, const Vec3& rate_rms, const double band[2],
                        int components = 24);
};

}  // namespace wheelins::sim
