// What the noise identification found (fusion/noise_adaptation.hpp), for people and
// programs: a summary for the run's printout, and noise.yaml beside the trajectory —
// per module the figures the run was given (from the manifest, or defaults), what the
// static period showed, what the motion showed, what was in use at the end, the
// consistency of every measurement type, the states not estimated and the estimates
// that left 3 sigma of their prior. Figures are in the manifest's keys and units, so a
// line can be pasted back into a manifest's `noise:` map.
#pragma once

#include <string>
#include <vector>

#include "wheelins/fusion/noise_adaptation.hpp"
#include "wheelins/io/manifest.hpp"

namespace wheelins {

/// The noise.yaml text. `manifest` tells which figures it stated (ModuleSpec::noise_stated).
std::string noise_report_yaml(const std::vector<ModuleNoiseReport>& reports,
                              const Manifest& manifest, bool adapted);

/// A few lines per module for the run's printout, then the warnings.
std::string noise_report_text(const std::vector<ModuleNoiseReport>& reports,
                              const Manifest& manifest, bool adapted);

}  // namespace wheelins
