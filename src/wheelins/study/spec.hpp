// A study: many navigation runs declared in one YAML file (docs/studies.md). Its axes
// multiply into independent jobs, numbered 0..N-1; job K is fully determined by the
// file and K, so any process on any machine can run any job, in any order.
//
//  * Conditions (`sweep:`): the rows of the report, e.g. platform x terrain x noise.
//  * Replicates (`seeds:` / `replicates:`): the samples the statistics are taken over
//    (seeds of the simulator, or chips of a recording); configurations are paired on them.
//  * Configurations (`configurations:`): the columns, e.g. single / body-wheel / triple.
// Job order: the first condition axis outermost, the configuration innermost, so the jobs
// that share a dataset are neighbours.
//
// A job's settings are dotted keys with values, in four namespaces:
//   simulate.KEY  a simulator setting (the scenario.yaml keys, e.g. simulate.errors.gyro_sf_ppm,
//                 or the `wheelins simulate` option names: preset, terrain, wheel_noise, only, ...)
//   run.KEY       a run-configuration key (docs/run-config.md, e.g. run.filter.velocity_gate),
//                 applied by the code that reads run-configuration files (load_run_config)
//   manifest.KEY  an edit of the dataset's manifest (modules.*.noise: null drops the noise figures)
//   dataset | seed | configuration | chips | chip | modules
// Later settings override earlier ones: the study's fixed settings, then the axes in order.
#pragma once

#include <yaml-cpp/yaml.h>

#include <cstdint>
#include <filesystem>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "wheelins/run/experiment.hpp"
#include "wheelins/run/run_config.hpp"
#include "wheelins/sim/config.hpp"
#include "wheelins/study/stats.hpp"

namespace wheelins::study {

/// One setting: a dotted key and its value, with where it was given (for messages).
struct Setting {
  std::string key;
  YAML::Node value;
  std::string where;  ///< the key path in the study file ("sweep.seed"), or the option
  std::size_t line = 0;  ///< its line in the study file (0: none, e.g. a generated setting)
  /// `where` with the line, for messages: "sweep.seed (line 7)".
  std::string origin() const { return line ? where + " (line " + std::to_string(line) + ")" : where; }
};

enum class AxisRole { kCondition, kReplicate, kConfiguration };

struct AxisValue {
  std::string label;
  std::vector<Setting> settings;
};

struct Axis {
  std::string name;
  AxisRole role = AxisRole::kCondition;
  std::vector<AxisValue> values;
};

/// The data of a job: an existing manifest, or simulator settings (generated into the
/// cache), and edits of the manifest (YAML text of a map of dotted keys, empty: none).
struct DatasetSpec {
  std::optional<std::filesystem::path> manifest;
  std::optional<sim::SimConfig> sim;
  std::string manifest_edits;
  /// Every setting of the data as text (SimConfig::to_yaml() and the hashes of the files
  /// it reads, or the manifest path and the hash of its text): equal text, same data. The
  /// manifest edits are not in it (one generated dataset serves every edit).
  std::string canonical;
  /// The cache directory's name (simulated data, or an edited manifest of existing data):
  /// readable settings and the hash of the text; empty when nothing is cached.
  std::string cache_name;
  std::string describe() const;  ///< "robot/field seed 3" or the manifest path
};

/// One job, fully resolved (plain values only: safe to hand to another thread).
struct Job {
  std::size_t index = 0;
  std::vector<std::size_t> choice;  ///< the value taken on each axis
  std::vector<std::string> labels;  ///< its label, per axis
  DatasetSpec dataset;
  std::string configuration;  ///< the configuration column's label
  /// The run configuration (the docs/run-config.md format) without `dataset`.
  std::string run_yaml;
  bool keep_series = false;  ///< keep the error series and track (experiment figures)
  /// The experiment's run this job is (built-in experiment studies), without results.
  std::optional<eval::ExperimentRun> experiment_run;
  std::string canonical;         ///< dataset + run settings: equal text, same job
  std::string key;               ///< 16 hex digits of the hash of `canonical`
  std::string describe() const;  ///< "robot, flat | seed 3 | triple"
};

/// The paper's experiment (`wheelins experiment`) as a built-in study: every chip
/// combination of eval::experiment_plan() on one dataset.
struct ExperimentSpec {
  std::filesystem::path dataset;
  std::vector<std::string> only;
  std::string speed = "own";  ///< the run default (FusionOptions::speed)
  double duration = 0.0;
  std::string calibration = "estimate";  ///< the run default (RunConfig::calibration)
};

struct LoadOptions {
  std::filesystem::path results_dir;  ///< overrides the file's `results` (e.g. a shared directory)
  std::filesystem::path cache_dir;    ///< overrides `cache`
};

class Study {
 public:
  /// Reads and checks a study file: InputError naming the file and key on any mistake
  /// (unknown keys with the closest known one, bad values, empty axes).
  static Study load(const std::filesystem::path& file, const LoadOptions& options = {});

  const std::filesystem::path& file() const { return file_; }
  const std::string& name() const { return name_; }
  const std::string& description() const { return description_; }
  const std::filesystem::path& results_dir() const { return results_; }
  const std::filesystem::path& cache_dir() const { return cache_; }
  std::filesystem::path jobs_dir() const { return results_ / "jobs"; }
  const std::vector<Axis>& axes() const { return axes_; }
  const std::optional<ExperimentSpec>& experiment() const { return experiment_; }
  const IntervalOptions& interval() const { return interval_; }
  /// Configuration pairs (a, b) whose paired differences b - a the report gives.
  const std::vector<std::pair<std::string, std::string>>& compare() const { return compare_; }
  /// The configuration labels (columns), in order.
  std::vector<std::string> configurations() const;

  std::size_t job_count() const;
  /// Job k resolved: its dataset, run configuration and canonical text. InputError for
  /// settings that do not go together (naming the job and the keys). Thread-safe (one job
  /// is resolved at a time: the YAML values are not safe to read from several threads).
  Job job(std::size_t k) const;
  /// Every job resolved and every distinct run configuration checked by load_run_config
  /// (so a misspelt key fails before any job runs). Returns the jobs.
  std::vector<Job> check_all() const;
  /// The jobs whose data are job k's (k included): the other values of the axes that do
  /// not change the data.
  std::vector<std::size_t> data_siblings(std::size_t k) const;
  /// `keep_datasets: false`: a simulated dataset is deleted when every job on it is done.
  bool keep_datasets() const { return keep_datasets_; }

 private:
  Job resolve(std::size_t k, const std::vector<std::size_t>& choice,
              const std::vector<Setting>& settings) const;
  std::filesystem::path file_, dir_, results_, cache_;
  std::string name_, description_;
  std::vector<Setting> fixed_;
  std::vector<Axis> axes_;
  IntervalOptions interval_;
  std::vector<std::pair<std::string, std::string>> compare_;
  std::optional<ExperimentSpec> experiment_;
  std::vector<eval::ExperimentRun> experiment_runs_;
  bool keep_datasets_ = true;
  std::shared_ptr<std::mutex> mutex_ = std::make_shared<std::mutex>();
  /// Simulator settings already resolved (their text -> the data, and every setting of the
  /// data as dotted key -> value for references), under mutex_.
  struct SimMemo {
    DatasetSpec data;
    std::map<std::string, std::string> values;
  };
  std::shared_ptr<std::map<std::string, SimMemo>> sim_memo_ =
      std::make_shared<std::map<std::string, SimMemo>>();
};

/// The run configuration of `run_yaml` on `manifest`, read by load_run_config (through a
/// temporary file): warnings (unknown keys) are InputErrors; messages name `where`.
RunConfig load_run_yaml(const std::string& run_yaml, const std::filesystem::path& manifest,
                        const std::string& where);

/// Checks a run configuration's text with load_run_config (the dataset key is filled in):
/// warnings (unknown keys) become InputErrors, named by `where`.
void check_run_yaml(const std::string& run_yaml, const std::string& where);

/// The study file text of the built-in experiment on `spec` (results in the file's directory).
std::string experiment_study_yaml(const ExperimentSpec& spec);
/// Checks the configurations of `experiment.only` (`wheelins experiment --only`): an unknown
/// one is an InputError "WHERE: unknown configuration 'X' (single, ...)"; the command checks
/// its option with this before it writes the study, so the error names the option.
void check_experiment_only(const std::vector<std::string>& only, const std::string& where);

/// "a.b.c" -> {"a", "b", "c"}.
std::vector<std::string> split_dotted(const std::string& key);

/// FNV-1a 64 of `text` as 16 hex digits.
std::string hash_text(const std::string& text);

/// A YAML value as one line of flow-style YAML ("null" when undefined or null).
std::string flow_yaml(const YAML::Node& value);

}  // namespace wheelins::study
