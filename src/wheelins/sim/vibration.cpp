// The module vibration of vibration.hpp: drawing it, and evaluating it exactly at a time
// or at a sample's four quadrature nodes.
#include "wheelins/sim/vibration.hpp"

#include <cmath>

namespace wheelins::sim {

void Vibration::eval(double t, JV& disp, JV& rot) const {
  for (int d = 0; d < 6; ++d) {
    J acc(0.0);
    for (const auto& c : dof[d]) {
      const double th = c.omega * t + c.phase;
      const double s = std::sin(th), co = std::cos(th), w = c.omega, a = c.amplitude;
      acc.c[0] += a * s;
      if constexpr (kOrder >= 1) acc.c[1] += a * w * co;
      if constexpr (kOrder >= 2) acc.c[2] -= a * w * w * s / 2.0;
      if constexpr (kOrder >= 3) acc.c[3] -= a * w * w * w * co / 6.0;
    }
    (d < 3 ? disp[d] : rot[d - 3]) = acc;
  }
}

void Vibration::prepare(const double offsets[4], double h) {
  step_h = h;
  since_exact = -1;
  for (int d = 0; d < 6; ++d) {
    node_phasors[d].clear();
    phase_state[d].clear();
    for (const auto& c : dof[d]) phase_state[d].push_back({0.0, 0.0, std::cos(c.omega * h), std::sin(c.omega * h)});
    for (const auto& c : dof[d]) {
      std::array<double, 8> ph;
      for (int i = 0; i < 4; ++i) {
        ph[2 * i] = std::cos(c.omega * offsets[i]);
        ph[2 * i + 1] = std::sin(c.omega * offsets[i]);
      }
      node_phasors[d].push_back(ph);
    }
  }
}

void Vibration::eval4(double t_mid, JV disp[4], JV rot[4]) {
  const bool exact = since_exact < 0 || since_exact >= 255 ||
                     std::abs(t_mid - last_mid - step_h) > 1e-9 * step_h;
  since_exact = exact ? 0 : since_exact + 1;
  last_mid = t_mid;
  for (int d = 0; d < 6; ++d) {
    J acc[4];
    for (std::size_t k = 0; k < dof[d].size(); ++k) {
      const Component& c = dof[d][k];
      const auto& ph = node_phasors[d][k];
      auto& st = phase_state[d][k];
      if (exact) {
        const double th = c.omega * t_mid + c.phase;
        st[0] = std::sin(th);
        st[1] = std::cos(th);
      } else {
        const double sn = st[0] * st[2] + st[1] * st[3];
        st[1] = st[1] * st[2] - st[0] * st[3];
        st[0] = sn;
      }
      const double s0 = st[0], c0 = st[1], w = c.omega, a = c.amplitude;
      for (int i = 0; i < 4; ++i) {
        const double s = s0 * ph[2 * i] + c0 * ph[2 * i + 1];  // sin(th + w off_i)
        const double co = c0 * ph[2 * i] - s0 * ph[2 * i + 1];
        acc[i].c[0] += a * s;
        if constexpr (kOrder >= 1) acc[i].c[1] += a * w * co;
        if constexpr (kOrder >= 2) acc[i].c[2] -= a * w * w * s / 2.0;
        if constexpr (kOrder >= 3) acc[i].c[3] -= a * w * w * w * co / 6.0;
      }
    }
    for (int i = 0; i < 4; ++i) (d < 3 ? disp[i][d] : rot[i][d - 3]) = acc[i];
  }
}

Vibration Vibration::draw(Rng& rng, const Vec3& accel_rms, const Vec3& rate_rms, const double band[2],
                          int components) {
  Vibration v;
  const double share = std::sqrt(2.0 / components);  // sum of K sines of amplitude A: RMS A sqrt(K/2)
  for (int d = 0; d < 6; ++d) {
    const double rms = d < 3 ? accel_rms[d] : rate_rms[d - 3];
    for (int i = 0; i < components; ++i) {
      Component c;
      c.omega = 2.0 * kPi * rng.uniform(band[0], band[1]);
      c.phase = rng.uniform(0.0, 2.0 * kPi);
      // Displacement amplitude from the acceleration amplitude (/ w^2); angle from rate (/ w).
      c.amplitude = rms * share / (d < 3 ? c.omega * c.omega : c.omega);
      if (rms > 0.0) v.dof[d].push_back(c);
    }
  }
  return v;
}

}  // namespace wheelins::sim
