// Fuzzes the configuration paths: the YAML loaders (dataset manifest, run configuration,
// study file with its first and last job resolved: the simulator settings and manifest
// edits it builds), the simulator's key=value settings (--set, and the options that map
// onto them), and the number checks every command-line number goes through (the run
// request's ranges, the evaluation options, the simulator's ranges). Mode = first byte % 5.
// One target for every YAML loader, so that the fuzzing time of the CI stays as it is.
#include <cstring>

#include "fuzz_common.hpp"
#include "wheelins/eval/metrics.hpp"
#include "wheelins/run/run.hpp"
#include "wheelins/run/run_config.hpp"
#include "wheelins/io/manifest.hpp"
#include "wheelins/sim/config.hpp"
#include "wheelins/study/spec.hpp"

using namespace wheelins;

namespace {

/// The next double of the input (0 when it runs out).
double take(const std::uint8_t*& p, const std::uint8_t* end) {
  double x = 0.0;
  if (end - p >= 8) {
    std::memcpy(&x, p, 8);
    p += 8;
  }
  return x;
}

void numbers(const std::uint8_t* p, const std::uint8_t* end) {
  Manifest m;
  m.path = "fuzz-manifest.yaml";
  for (const char* name : {"left-C1", "right-C1", "body-C1"}) {
    ModuleSpec s;
    s.name = name;
    s.kind = name[0] == 'b' ? ModuleKind::kBody : ModuleKind::kWheel;
    s.rate_hz = take(p, end);
    m.modules.push_back(s);
  }
  RunRequest r;
  r.manifest = m;
  r.modules = {"left-C1", "right-C1", "body-C1"};
  r.max_duration = take(p, end);
  r.nav.output_interval = take(p, end);
  r.nav.covariance_interval = take(p, end);
  r.nav.faults.max_gap = take(p, end);
  r.nav.fusion.centralized = end > p && (*p & 1);
  for (int i = 0; i < 3; ++i) r.nav.fusion.weights.push_back(take(p, end));
  try {
    validate_run_request(r);
  } catch (const InputError&) {
  }
  eval::EvalOptions eo;
  eo.segment_length = take(p, end);
  eo.max_gap = take(p, end);
  try {
    eval::Evaluator e(earth::LocalFrame({0.5, 2.0, 10.0}), {}, eo, false);
  } catch (const InputError&) {
  }
  sim::SimConfig c;
  c.duration = take(p, end);
  c.speed = take(p, end);
  c.rate_hz = take(p, end);
  c.static_duration = take(p, end);
  c.terrain_slope_deg = take(p, end);
  c.vehicle.wheel_radius = take(p, end);
  try {
    c.validate();
  } catch (const InputError&) {
  }
}

void settings(const std::uint8_t* data, std::size_t size) {
  sim::SimConfig c;
  const std::string text(reinterpret_cast<const char*>(data), size);
  std::size_t pos = 0;
  try {
    while (pos < text.size()) {
      std::size_t nl = text.find('\n', pos);
      if (nl == std::string::npos) nl = text.size();
      c.apply_setting(text.substr(pos, nl - pos));
      pos = nl + 1;
    }
    c.validate();
  } catch (const InputError&) {
  }
}

void study_file(const std::filesystem::path& file) {
  const study::Study s = study::Study::load(file);
  if (s.job_count() == 0) return;
  (void)s.job(0);
  (void)s.job(s.job_count() - 1);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 1) return 0;
  static const auto file = fuzz::scratch_file("config.yaml");
  const WarningSink quiet = [](const std::string&) {};
  try {
    switch (data[0] % 5) {
      case 0: fuzz::write_bytes(file, data + 1, size - 1); load_manifest(file, quiet); break;
      case 1: fuzz::write_bytes(file, data + 1, size - 1); load_run_config(file, quiet); break;
      case 2: settings(data + 1, size - 1); break;
      case 4: fuzz::write_bytes(file, data + 1, size - 1); study_file(file); break;
      default: numbers(data + 1, data + size); break;
    }
  } catch (const InputError&) {
  }
  return 0;
}
