// noise.yaml and the run's noise summary (noise_report.hpp).
#include "wheelins/run/noise_report.hpp"

#include <cmath>
#include <cstdio>
#include <sstream>

#include "wheelins/filter/error_state.hpp"

namespace wheelins {

namespace {

// Human units of the manifest's noise keys.
double arw_h(double x) { return x / kDeg * 60.0; }         // deg/sqrt(h)
double vrw_h(double x) { return x * 60.0; }                // m/s/sqrt(h)
double deg_h(double x) { return x / kDeg * 3600.0; }       // deg/h

std::string num(double v, int digits = 4) {
  if (!std::isfinite(v)) return ".nan";
  char b[40];
  std::snprintf(b, sizeof b, "%.*g", digits, v);
  return b;
}

std::string vec(const Vec3& v, int digits = 4) {
  return "[" + num(v.x(), digits) + ", " + num(v.y(), digits) + ", " + num(v.z(), digits) + "]";
}


const ModuleSpec* spec_of(const Manifest& m, const std::string& name) { return m.find(name); }

/// "manifest" or "default" for one noise key of a module.
const char* source(const ModuleSpec* s, std::uint16_t bit) {
  return s && (s->noise_stated & bit) ? "manifest" : "default";
}

void consistency(std::ostringstream& o, const char* name, const MeasurementConsistency& c) {
  if (!c.updates) return;
  o << "      " << name << ": {updates: " << c.updates << ", mean_nis: " << num(c.mean_nis(), 3)
    << ", expected: " << c.dim << ", over_99_9_pct: "
    << num(100.0 * static_cast<double>(c.over) / static_cast<double>(c.updates), 3)
    << ", rejected: " << c.rejected << "}\n";
}

/// The figures the run started from, with where each came from.
void given_section(std::ostringstream& o, const ModuleNoiseReport& r, const ModuleSpec* s) {
  o << "    given:\n";
  o << "      gyro_arw_deg_sqrt_h: " << num(arw_h(r.given.gyro_arw)) << "  # " << source(s, kNoiseArw) << "\n";
  o << "      acc_vrw_m_s_sqrt_h: " << num(vrw_h(r.given.acc_vrw)) << "  # " << source(s, kNoiseVrw) << "\n";
  o << "      gyro_bias_deg_h: " << num(deg_h(r.given.gyro_bias_std)) << "  # " << source(s, kNoiseGyroBias) << "\n";
  o << "      acc_bias_m_s2: " << num(r.given.acc_bias_std) << "  # " << source(s, kNoiseAccBias) << "\n";
  o << "      gyro_sf_ppm: " << num(r.given.gyro_sf_std * 1e6) << "  # " << source(s, kNoiseGyroSf) << "\n";
  o << "      acc_sf_ppm: " << num(r.given.acc_sf_std * 1e6) << "  # " << source(s, kNoiseAccSf) << "\n";
  o << "      velocity_std_m_s: " << vec(r.velocity_std_given) << "  # the run's filter setting\n";
}

/// The Allan variance of the static period, or null without one.
void at_rest_section(std::ostringstream& o, const ModuleNoiseReport& r) {
  if (r.gyro_rest.valid) {
    o << "    at_rest:  # " << num(r.gyro_rest.duration, 4) << " s of static data\n";
    o << "      gyro_arw_deg_sqrt_h: " << num(arw_h(r.gyro_rest.white)) << "  # per axis "
      << vec(r.gyro_rest.white_axes / kDeg * 60.0) << " at tau " << num(r.gyro_rest.white_tau, 3) << " s\n";
    o << "      acc_vrw_m_s_sqrt_h: " << num(vrw_h(r.accel_rest.white)) << "  # per axis "
      << vec(r.accel_rest.white_axes * 60.0) << " at tau " << num(r.accel_rest.white_tau, 3) << " s\n";
    o << "      gyro_bias_instability_deg_h: " << num(deg_h(r.gyro_rest.bias_instability))
      << "  # " << (r.gyro_rest.floor_reached ? "Allan minimum at " : "an upper bound: still falling at ")
      << num(r.gyro_rest.bias_tau, 3) << " s\n";
    o << "      acc_bias_instability_m_s2: " << num(r.accel_rest.bias_instability)
      << "  # " << (r.accel_rest.floor_reached ? "Allan minimum at " : "an upper bound: still falling at ")
      << num(r.accel_rest.bias_tau, 3) << " s\n";
    o << "      gyro_bias_after_alignment_deg_h: " << num(deg_h(r.gyro_bias_start_sigma))
      << "  # 1 sigma of the aligned bias\n";
  } else {
    o << "    at_rest: null  # too few static samples for the Allan variance\n";
  }
}

/// What the velocity innovations showed, and the figures in use at the end.
void in_motion_and_used_sections(std::ostringstream& o, const ModuleNoiseReport& r) {
  o << "    in_motion:\n";
  o << "      estimated: " << (r.adapted ? "true" : "false") << "\n";
  o << "      acc_vrw_m_s_sqrt_h: " << num(vrw_h(r.vrw)) << "  # started from " << num(vrw_h(r.vrw_start)) << "\n";
  o << "      velocity_std_m_s: " << vec(r.velocity_std) << "  # speed, lateral, vertical\n";
  o << "      innovation_ratio: " << vec(r.nis_axes, 3)
    << "  # mean dz^2 / predicted per axis over the last window (1 if consistent)\n";
  o << "    used:\n";
  o << "      gyro_arw_deg_sqrt_h: " << num(arw_h(r.arw)) << "\n";
  o << "      acc_vrw_m_s_sqrt_h: " << num(vrw_h(r.vrw)) << "\n";
  o << "      gyro_bias_deg_h: " << num(deg_h(r.gyro_bias_instability)) << "  # in-run instability\n";
}

/// The states held or estimated from the constraint only, and the estimates beyond 3 sigma.
void state_sections(std::ostringstream& o, const ModuleNoiseReport& r) {
  o << "    not_estimated: [";
  for (std::size_t k = 0; k < r.held.size(); ++k) o << (k ? ", " : "") << error_state_name(r.held[k]);
  o << "]  # held at 0 (docs/filter.md 13.4: yaw-rate scale factors, the axle accelerometer's)\n";
  o << "    from_constraint_only: [";
  for (std::size_t k = 0; k < r.constraint_only.size(); ++k)
    o << (k ? ", " : "") << error_state_name(r.constraint_only[k]);
  o << "]  # estimated from the position constraint, not the velocity updates (13.4)\n";
  o << "    beyond_3_sigma:";
  if (r.excursions.empty()) o << " []";
  o << "\n";
  for (const PriorExcursion& x : r.excursions) {
    const bool gb = x.state >= BG && x.state < BG + 3, ab = x.state >= BA && x.state < BA + 3;
    const double u = gb ? 3600.0 / kDeg : (ab ? 1.0 : 1e6);
    o << "      - {state: " << error_state_name(x.state) << ", t_s: " << num(x.t, 10) << ", value: "
      << num(x.value * u) << ", prior_sigma: " << num(x.prior_sigma * u) << ", unit: "
      << (gb ? "deg/h" : (ab ? "m/s^2" : "ppm")) << "}\n";
  }
}

/// The module's warnings, quoted.
void warnings_section(std::ostringstream& o, const ModuleNoiseReport& r) {
  o << "    warnings:";
  if (r.warnings.empty()) o << " []";
  o << "\n";
  for (const std::string& w : r.warnings) {
    std::string q;
    for (char c : w) q += (c == '"' || c == '\\') ? std::string("\\") + c : std::string(1, c);
    o << "      - \"" << q << "\"\n";
  }
}

}  // namespace

std::string noise_report_yaml(const std::vector<ModuleNoiseReport>& reports,
                              const Manifest& manifest, bool adapted) {
  std::ostringstream o;
  o << "# wheelins run: the noise model, given and identified from the data (docs/filter.md "
       "section 13).\n"
       "# given: the figures the run started from (from the manifest, or the defaults);\n"
       "# at_rest: the Allan variance of the static period; in_motion: the velocity innovations\n"
       "# (Mehra's correlation method); used: in use at the end. Keys and units as in a\n"
       "# manifest's noise: map, so a line can be pasted back.\n";
  o << "format: wheelins-noise-1\n";
  o << "adapted: " << (adapted ? "true" : "false") << "  # false: the given figures were held fixed\n";
  o << "modules:\n";
  for (const ModuleNoiseReport& r : reports) {
    o << "  - name: \"" << r.module << "\"\n";
    o << "    kind: " << (r.wheel ? "wheel" : "body") << "\n";
    given_section(o, r, spec_of(manifest, r.module));
    at_rest_section(o, r);
    in_motion_and_used_sections(o, r);
    o << "    consistency:\n";
    consistency(o, "velocity", r.velocity);
    consistency(o, "position", r.position);
    state_sections(o, r);
    warnings_section(o, r);
  }
  return o.str();
}

std::string noise_report_text(const std::vector<ModuleNoiseReport>& reports,
                              const Manifest& manifest, bool adapted) {
  std::ostringstream o;
  char b[300];
  o << "noise model " << (adapted ? "(identified from the data):" : "(the given figures, held fixed):") << "\n";
  for (const ModuleNoiseReport& r : reports) {
    const ModuleSpec* s = spec_of(manifest, r.module);
    std::snprintf(b, sizeof b,
                  "  %-12s ARW %.3g deg/sqrt(h) (%s %.3g)  VRW %.3g m/s/sqrt(h) (%s %.3g)  "
                  "velocity sigma %.3g/%.3g/%.3g m/s  velocity NIS %.2f of 3\n",
                  r.module.c_str(), arw_h(r.arw), source(s, kNoiseArw), arw_h(r.given.gyro_arw),
                  vrw_h(r.vrw), source(s, kNoiseVrw), vrw_h(r.given.acc_vrw), r.velocity_std.x(),
                  r.velocity_std.y(), r.velocity_std.z(), r.velocity.mean_nis());
    o << b;
  }
  for (const ModuleNoiseReport& r : reports)
    for (const std::string& w : r.warnings) o << "  warning: " << w << "\n";
  return o.str();
}

}  // namespace wheelins
