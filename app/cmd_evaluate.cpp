// `wheelins evaluate`: accuracy of a trajectory against a truth file (paper VI-B).
#include <charconv>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "cli.hpp"
#include "wheelins/eval/metrics.hpp"
#include "wheelins/io/atomic_file.hpp"
#include "wheelins/io/truth_text.hpp"
#include "wheelins/nav/types.hpp"

namespace {

using namespace wheelins;

struct Options {
  std::string truth, traj, format = "auto", truth_layout = "auto";
  double segment = 100.0;
  double max_gap = 5.0;
  bool align = false, align_se2 = false, align_origin = false;
  double align_start = 0.0;
  bool force = false;
  std::string json, series, origin, frame, export_truth;
  std::string antenna, truth_columns, truth_frame, truth_origin;
  double truth_time_scale = 1.0, truth_time_offset = 0.0;
  bool truth_keep_repeats = false;
};

// "a,b,c" as three finite numbers; `flag` and `expected` name them in the messages.
std::vector<double> parse_three(const std::string& flag, const std::string& text, const char* expected) {
  std::vector<double> v;
  std::size_t start = 0;
  while (start <= text.size()) {
    const std::size_t k = text.find(',', start);
    std::string part = text.substr(start, k == std::string::npos ? std::string::npos : k - start);
    while (!part.empty() && part.front() == ' ') part.erase(part.begin());
    while (!part.empty() && part.back() == ' ') part.pop_back();
    double x = 0.0;
    const auto r = std::from_chars(part.data(), part.data() + part.size(), x);
    if (part.empty() || r.ec != std::errc() || r.ptr != part.data() + part.size() ||
        !std::isfinite(x))
      throw InputError(flag + " '" + text + "': '" + part + "' is not a number (expected " + expected + ")");
    v.push_back(x);
    if (k == std::string::npos) break;
    start = k + 1;
  }
  if (v.size() != 3)
    throw InputError(flag + " '" + text + "': expected 3 values " + expected + ", got " +
                     std::to_string(v.size()));
  return v;
}

earth::Geodetic parse_geodetic(const std::string& flag, const std::string& text) {
  const std::vector<double> v = parse_three(flag, text, "lat_deg,lon_deg,h_m");
  if (std::abs(v[0]) > 90.0 || std::abs(v[1]) > 180.0)
    throw InputError(flag + " '" + text + "': latitude/longitude out of range");
  return {v[0] * kDeg, v[1] * kDeg, v[2]};
}

std::string fmt(double v, int decimals, const char* unit = "") {
  if (!std::isfinite(v)) return "n/a";
  char buf[64];
  std::snprintf(buf, sizeof(buf), "%.*f%s", decimals, v, unit);
  return buf;
}

// One line of the table: the name padded to a column, then the value.
void row(std::ostream& os, const char* name, const std::string& value) {
  char buf[48];
  std::snprintf(buf, sizeof(buf), "  %-26s", name);
  os << buf << value << "\n";
}

// What was done to the inputs before comparing them: the antenna lever arm, the truth time offset.
std::string applied_text(const eval::EvalResult& r) {
  std::string applied;
  if (!r.antenna.isZero())
    applied += "antenna at " + fmt(r.antenna.x(), 3) + " / " + fmt(r.antenna.y(), 3) + " / " +
               fmt(r.antenna.z(), 3) + " m (forward / right / down) from the trajectory's point";
  if (r.truth_time_offset != 0.0)
    applied += std::string(applied.empty() ? "" : "; ") + "truth time offset " +
               (r.truth_time_offset > 0 ? "+" : "") + fmt(r.truth_time_offset, 6, " s");
  return applied.empty() ? std::string("no antenna lever arm, no truth time offset") : applied;
}

// The table's head: the two inputs, what was applied to them and the truth's quality.
void print_inputs(std::ostream& os, const eval::EvalResult& r, const TruthData& truth) {
  os << "trajectory: " << r.traj_file << " (" << r.traj_format << ", " << r.traj_records
     << " records)\n";
  os << "truth:      " << r.truth_file << " (" << truth_layout_name(truth.layout) << ", "
     << r.truth_records << " records)\n";
  if (!truth.description.empty()) os << "            " << truth.description << "\n";
  os << "applied:    " << applied_text(r) << "\n";
  os << "truth quality: " << eval::describe_truth_quality(r.truth_quality);
}

// The truth epochs evaluated, and why the others were left out.
std::string evaluated_text(const eval::EvalResult& r) {
  std::string epochs = std::to_string(r.epochs) + " truth epochs";
  if (r.skipped_outside || r.skipped_gap || r.skipped_truth_jump || r.skipped_sparse) {
    epochs += " (" + std::to_string(r.skipped_outside) + " outside the trajectory, " +
              std::to_string(r.skipped_gap) + " in its gaps";
    if (r.skipped_sparse)
      epochs += ", " + std::to_string(r.skipped_sparse) + " between records sparser than the truth";
    if (r.skipped_truth_jump) epochs += ", " + std::to_string(r.skipped_truth_jump) + " left out at truth jumps";
    epochs += ")";
  }
  return epochs;
}

std::string drift_text(const eval::EvalResult& r) {
  std::string drift = fmt(r.drift_rate * 100.0, 3, " %");
  if (r.drift_curve.empty())
    drift += "  (distance shorter than one " + fmt(r.segment_length, 0, " m") + " segment)";
  else
    drift += "  (mean of " + std::to_string(r.drift_curve.size()) + " segments of " +
             fmt(r.segment_length, 0, " m") + ")";
  return drift;
}

void print_heading(std::ostream& os, const eval::EvalResult& r) {
  if (r.heading_source == "course") {
    row(os, "heading RMSE (course)",
        r.has_heading ? fmt(r.heading_rmse / kDeg, 3, " deg") + "  (from the course: the truth has no heading; max " +
                            fmt(r.heading_max_abs / kDeg, 2, " deg") + ", " + std::to_string(r.heading_epochs) +
                            " epochs moving >= 1 m/s)"
                      : std::string("n/a (the truth has no heading and its course was never usable: "
                                    "slower than 1 m/s)"));
  } else {
    row(os, "heading RMSE", r.has_heading ? fmt(r.heading_rmse / kDeg, 3, " deg") +
                                                "  (max " + fmt(r.heading_max_abs / kDeg, 2, " deg") + ")"
                                          : "n/a (no heading in truth or trajectory)");
  }
}

// The alignment row, when the trajectory was aligned onto the truth.
void print_alignment(std::ostream& os, const eval::EvalResult& r) {
  if (r.aligned && r.align_start > 0.0)
    row(os, "alignment", "start aligned over the truth's first " + fmt(r.align_start, 0, " m") + ": rotation " +
                             fmt(r.align_yaw / kDeg, 3, " deg") + ", shift n/e " + fmt(r.align_offset.x(), 3) + " / " +
                             fmt(r.align_offset.y(), 3) + " m (fit residual " + fmt(r.align_residual, 3, " m") + ")");
  else if (r.align_method == "se3" || r.align_method == "se2")
    row(os, "alignment", std::string(r.align_method == "se3" ? "SE(3)" : "SE(2), about the vertical,") +
                             " fit of the whole trajectory onto the truth over " + std::to_string(r.align_points) +
                             " epochs: rotation roll/pitch/yaw " + fmt(r.align_rpy.x() / kDeg, 3) + " / " +
                             fmt(r.align_rpy.y() / kDeg, 3) + " / " + fmt(r.align_rpy.z() / kDeg, 3) +
                             " deg, shift n/e/d " + fmt(r.align_offset.x(), 3) + " / " + fmt(r.align_offset.y(), 3) +
                             " / " + fmt(r.align_offset.z(), 3) + " m (fit rms " + fmt(r.align_residual, 3, " m") + ")");
  else if (r.aligned)
    row(os, "alignment", "origin (first epoch): shift n/e/d " + fmt(r.align_offset.x(), 3) + " / " +
                             fmt(r.align_offset.y(), 3) + " / " + fmt(r.align_offset.z(), 3) +
                             " m, " +
                             (r.align_rotated ? "rotation " + fmt(r.align_yaw / kDeg, 3, " deg")
                                              : std::string("no rotation (heading unavailable)")));
}

void print_table(std::ostream& os, const eval::EvalResult& r, const TruthData& truth) {
  print_inputs(os, r, truth);
  row(os, "evaluated", evaluated_text(r));
  row(os, "coverage", fmt(r.coverage * 100.0, 1, " %") + " of the truth's " + fmt(r.truth_span, 1, " s") +
                          (r.comparable ? "" : "  NOT COMPARABLE with a full trajectory's figures"));
  row(os, "duration", fmt(r.duration, 2, " s") + "  (" + fmt(r.t_start, 3) + " .. " +
                          fmt(r.t_end, 3) + ")");
  row(os, "distance", fmt(r.distance, 1, " m"));
  row(os, "position drift rate", drift_text(r));
  row(os, "final error / distance", fmt(r.final_error_ratio * 100.0, 3, " %"));
  print_heading(os, r);
  row(os, "max horizontal error", fmt(r.max_error, 3, " m"));
  row(os, "final horizontal error", fmt(r.final_error, 3, " m"));
  row(os, "RMS horizontal error", fmt(r.rms_error, 3, " m"));
  if (r.has_sigma)
    row(os, "within 3 sigma (horiz.)", fmt(r.within_3sigma * 100.0, 1, " %") + "  (mean NEES " +
                                           fmt(r.mean_nees, 2) + ", expected 2; " +
                                           std::to_string(r.sigma_epochs) + " epochs)");
  else
    row(os, "within 3 sigma (horiz.)", "n/a (no north/east std in the trajectory)");
  if (const std::string w = eval::sigma_warning(r); !w.empty())
    std::fprintf(stderr, "warning: %s\n", w.c_str());
  if (const std::string w = eval::coverage_warning(r); !w.empty())
    std::fprintf(stderr, "warning: %s\n", w.c_str());
  print_alignment(os, r);
}

void write_series(const std::string& file, const eval::EvalResult& r, bool force) {
  AtomicTextFile out(file, force);
  out.write(
      "t_s,distance_m,err_n_m,err_e_m,err_d_m,err_h_m,heading_err_deg,sigma_h_m,nees_h\n");
  for (const auto& e : r.series) {
    std::string& b = out.buffer();
    const double vals[9] = {e.t,           e.distance,     e.err_ned.x(),
                            e.err_ned.y(), e.err_ned.z(),  e.err_h,
                            e.heading_err / kDeg, e.sigma_h, e.nees_h};
    for (int k = 0; k < 9; ++k) {
      if (k) b += ',';
      append_double(b, vals[k], k == 0 ? 0 : 10);
    }
    b += '\n';
    out.maybe_flush();
  }
  out.commit();
}

// The truth as TUM in `frame` (its origin in the header), times shifted by `offset`.
void export_truth_tum(const std::string& file, const TruthData& truth, const earth::LocalFrame& frame, TumFrame f,
                      double offset, bool force) {
  TrajectoryWriterOptions w;
  w.overwrite = force;
  w.tum_frame = f;
  w.origin = frame.origin();
  const auto out = make_trajectory_writer(TrajectoryFormat::kTum, file, w);
  for (const TruthRecord& r : truth.records) {
    TrajectoryRecord t;
    t.t = r.t + offset;
    t.p_inN = frame.ned_from_geodetic(r.lla);
    t.rpy = truth.has_attitude ? r.rpy : Vec3::Zero();
    out->write(t);
  }
  out->commit();
}

void check_numbers(const Options& o) {
  if (!(o.segment >= eval::kMinSegment && o.segment <= eval::kMaxSegment))
    throw InputError("--segment " + std::to_string(o.segment) + ": must be in [1, 1e6] m");
  if (!(o.max_gap > 0.0 && o.max_gap <= 3600.0))
    throw InputError("--max-gap " + std::to_string(o.max_gap) + ": must be in (0, 3600] s");
  if (!(std::isfinite(o.truth_time_scale) && o.truth_time_scale > 0.0))
    throw InputError("--truth-time-scale " + std::to_string(o.truth_time_scale) + ": must be > 0");
  if (!std::isfinite(o.truth_time_offset))
    throw InputError("--truth-time-offset: must be a finite number of seconds");
}

// Every output checked before anything is read or written (all or nothing); none is an input.
void check_outputs(const Options& o) {
  std::vector<OutputFile> outputs;
  if (!o.json.empty() && o.json != "-") outputs.push_back({o.json, "--json"});
  if (!o.series.empty()) outputs.push_back({o.series, "--series"});
  if (!o.export_truth.empty()) outputs.push_back({o.export_truth, "--export-truth"});
  check_output_files(outputs, {{o.truth, "the truth (--truth)"}, {o.traj, "the trajectory (--traj)"}}, o.force);
}

TruthReadOptions truth_read_options(const Options& o) {
  TruthReadOptions read;
  read.time_scale = o.truth_time_scale;
  read.collapse_repeated = !o.truth_keep_repeats;
  if (!o.truth_columns.empty()) set_truth_columns(read, o.truth_columns);
  if (!o.truth_frame.empty()) read.tum_frame = tum_frame_from_name(o.truth_frame);
  if (!o.truth_origin.empty()) read.tum_origin = parse_geodetic("--truth-origin", o.truth_origin);
  return read;
}

eval::EvalOptions eval_options(const Options& o) {
  eval::EvalOptions opt;
  opt.segment_length = o.segment;
  opt.max_gap = o.max_gap;
  opt.align_origin = o.align_origin;
  opt.align_fit = o.align ? eval::AlignFit::kSe3 : o.align_se2 ? eval::AlignFit::kSe2 : eval::AlignFit::kNone;
  opt.align_start = o.align_start;
  opt.truth_time_offset = o.truth_time_offset;
  if (!o.antenna.empty()) {
    const std::vector<double> l = parse_three("--antenna", o.antenna, "x,y,z in metres");
    opt.antenna = Vec3(l[0], l[1], l[2]);
  }
  return opt;
}

// The truth in `layout` (detected when auto); the options of another layout refused.
TruthData read_truth_input(const Options& o, TruthLayout layout, const TruthReadOptions& read) {
  const TruthLayout found = layout == TruthLayout::kAuto ? detect_truth_layout(o.truth) : layout;
  if (found != TruthLayout::kTum && (!o.truth_origin.empty() || !o.truth_frame.empty()))
    throw InputError("--truth-origin and --truth-frame are for a TUM truth; '" + o.truth +
                     "' is " + truth_layout_name(found));
  if (found != TruthLayout::kText && (!o.truth_columns.empty() || o.truth_keep_repeats))
    throw InputError("--truth-columns and --truth-keep-repeats are for a text truth; '" + o.truth +
                     "' is " + truth_layout_name(found));
  return read_truth(o.truth, found, read);
}

// The trajectory in `format` (detected when auto), in --frame when it is a TUM file.
TrajectoryData read_trajectory_input(const Options& o, TrajectoryFormat format) {
  const TrajectoryFormat traj_format = format == TrajectoryFormat::kAuto ? detect_trajectory_format(o.traj) : format;
  TrajectoryReadOptions traj_read;
  if (!o.frame.empty()) {
    const TumFrame f = tum_frame_from_name(o.frame);
    if (traj_format == TrajectoryFormat::kTum) traj_read.tum_frame = f;
    else if (o.export_truth.empty())
      throw InputError("--frame " + o.frame + ": it is the frame of a TUM trajectory or of --export-truth; '" +
                       o.traj + "' is " + trajectory_format_name(traj_format) + " and nothing is exported");
  }
  return read_trajectory(o.traj, traj_format, traj_read);
}

// What the table's figures leave unsaid: a partial evaluation, an assumed origin or frame.
void print_notes(std::ostream& table, const Options& o, const TrajectoryData& traj,
                 const eval::EvalResult& res) {
  if (!traj.records.empty()) {
    const double span = traj.records.back().t - traj.records.front().t;
    if (res.duration < 0.95 * span - 1.0)
      std::cerr << "warning: the evaluation covers " << fmt(res.duration, 1, " s") << " of the "
                << fmt(span, 1, " s") << " trajectory: the truth is shorter, has a gap or a "
                << "clock jump (" << res.skipped_outside << " truth epochs outside the trajectory, "
                << res.skipped_gap << " in its gaps); the figures are for that part only\n";
  }
  if (!traj.has_lla && !res.aligned && o.origin.empty() && !traj.origin)
    table << "note: " << o.traj << " has north/east/down only and names no origin; it was taken to be "
          << "relative to the first truth record (use --origin or an alignment otherwise)\n";
  if (traj.format == TrajectoryFormat::kTum)
    table << "trajectory frame: " << tum_frame_name(traj.tum_frame)
          << (traj.frame_assumed ? " (assumed: the file has no '# frame:' line; --frame to say)" : "") << "\n";
}

void write_json(const Options& o, const eval::EvalResult& res) {
  const std::string json = eval::to_json(res);
  if (o.json == "-") {
    std::cout << json;
  } else if (!o.json.empty()) {
    AtomicTextFile out(o.json, o.force);
    out.write(json);
    out.commit();
  }
}

// --export-truth: in the trajectory's TUM frame, else --frame, else ned.
void write_truth_export(const Options& o, const TruthData& truth, const TrajectoryData& traj,
                        const earth::LocalFrame& frame) {
  const TumFrame f = traj.format == TrajectoryFormat::kTum ? traj.tum_frame
                     : o.frame.empty()                     ? TumFrame::kNed
                                                           : tum_frame_from_name(o.frame);
  export_truth_tum(o.export_truth, truth, frame, f, o.truth_time_offset, o.force);
  std::cerr << "truth written to " << o.export_truth << " (TUM, " << tum_frame_name(f) << ", "
            << truth.records.size() << " records"
            << (truth.has_attitude ? "" : "; the truth has no attitude: its quaternions are the identity, "
                                          "compare positions only")
            << ")\n";
}

int run(const Options& o) {
  check_numbers(o);
  const TruthLayout layout = truth_layout_from_name(o.truth_layout);
  const TrajectoryFormat format = trajectory_format_from_name(o.format);
  if (format == TrajectoryFormat::kKml)
    throw InputError("--format kml: KML is written for viewing only and cannot be evaluated");
  check_outputs(o);
  if (int(o.align) + int(o.align_se2) + int(o.align_origin) + int(o.align_start > 0.0) > 1)
    throw InputError("two alignments asked for: give one of --align, --align-se2, --align-origin and --align-start");

  const TruthReadOptions read = truth_read_options(o);
  const eval::EvalOptions opt = eval_options(o);
  const TruthData truth = read_truth_input(o, layout, read);
  const TrajectoryData traj = read_trajectory_input(o, format);
  // The local frame: --origin, else the origin a TUM trajectory names, else the first truth record.
  const earth::LocalFrame frame(!o.origin.empty() ? parse_geodetic("--origin", o.origin)
                                : traj.origin     ? *traj.origin
                                                  : truth.records.front().lla);
  const eval::EvalResult res = eval::evaluate(truth, traj, frame, opt);

  // With JSON on stdout the table goes to stderr, so stdout stays parseable.
  std::ostream& table = o.json == "-" ? std::cerr : std::cout;
  print_table(table, res, truth);
  print_notes(table, o, traj, res);
  write_json(o, res);
  if (!o.series.empty()) write_series(o.series, res, o.force);
  if (!o.export_truth.empty()) write_truth_export(o, truth, traj, frame);
  return 0;
}

const bool registered = cli::register_command(
    30, "evaluate", "Accuracy of a trajectory against a truth file (drift rate, heading RMSE)",
    [](CLI::App& sub) {
      auto o = std::make_shared<Options>();
      sub.add_option("--truth", o->truth,
                     "Truth file: GINS.bin (11 or 5 float64 columns), a GNSS track as CSV/text "
                     "(time, lat, lon, height columns by header name) or a TUM file")
          ->required();
      sub.add_option("--traj", o->traj, "Trajectory to judge (wheelins CSV, TUM, Wheel-INS traj.txt)")
          ->required();
      sub.add_option("--format", o->format, "Trajectory format: auto|csv|tum|wheelins-traj")
          ->capture_default_str();
      sub.add_option("--truth-layout", o->truth_layout, "Truth layout: auto|gins11|pos5|text|tum")
          ->capture_default_str();
      sub.add_option("--truth-columns", o->truth_columns,
                     "Text truth columns TIME,LAT,LON,HEIGHT (header names or 0-based indices; "
                     "default: found by header name)");
      sub.add_option("--truth-time-scale", o->truth_time_scale,
                     "Multiplies the truth's times on read (e.g. 0.1 for a column counting tenths of a second)")
          ->capture_default_str();
      sub.add_option("--truth-time-offset", o->truth_time_offset, "Added to the truth's times [s]")
          ->capture_default_str();
      sub.add_flag("--truth-keep-repeats", o->truth_keep_repeats,
                   "Text truth: keep rows repeating the previous fix (default: one fix, at its first row)");
      sub.add_option("--truth-frame", o->truth_frame,
                     "TUM truth: its local frame, enu (body x forward, y left, z up; ROS, evo) or ned "
                     "(body x forward, y right, z down); default: the file's '# frame:' line, else enu");
      sub.add_option("--truth-origin", o->truth_origin,
                     "TUM truth: the geodetic origin of its local frame, lat_deg,lon_deg,h_m (default: the "
                     "file's '# origin:' line)");
      sub.add_option("--frame", o->frame,
                     "TUM files: the trajectory's frame (default: its '# frame:' line, else ned) and the one "
                     "--export-truth writes in: ned (x north, y east, z down) or enu (x east, y north, z up; "
                     "ROS, evo)");
      sub.add_option("--export-truth", o->export_truth,
                     "Write the truth as a TUM file in the evaluation's local frame (the trajectory's frame "
                     "and origin when it is a TUM file), times with --truth-time-offset added: "
                     "`evo_ape tum FILE TRAJ.tum` then compares what this evaluation compares");
      sub.add_option("--antenna", o->antenna,
                     "The truth's antenna in the vehicle frame from the trajectory's point, x,y,z [m] "
                     "(x forward, y right, z down)");
      sub.add_option("--segment", o->segment, "Drift-rate segment length l [m]")
          ->capture_default_str();
      sub.add_option("--max-gap", o->max_gap,
                     "Largest trajectory time gap interpolated across [s]")
          ->capture_default_str();
      sub.add_flag("-a,--align", o->align,
                   "Rotate and shift the whole trajectory onto the truth, the SE(3) least-squares fit over "
                   "every evaluated epoch (Umeyama; evo_ape --align)");
      sub.add_flag("--align-se2", o->align_se2,
                   "As --align, the rotation about the vertical only (a ground vehicle's heading and "
                   "position offset)");
      sub.add_flag("--align-origin,--align_origin", o->align_origin,
                   "Shift and rotate the trajectory so its first evaluated epoch matches the truth's position "
                   "and heading (evo_ape --align_origin)");
      sub.add_option("--align-start", o->align_start,
                     "Rotate and shift the trajectory so its first METRES of travel lie on the truth's (a run "
                     "without an initial heading, in a local frame; the heading taken from the reference at the "
                     "start, as the paper does); 0: off")
          ->capture_default_str();
      sub.add_option("--json", o->json, "Write the metrics as JSON to FILE ('-' for stdout)");
      sub.add_option("--series", o->series, "Write per-epoch errors as CSV to FILE");
      sub.add_option("--origin", o->origin,
                     "Local frame origin lat_deg,lon_deg,h_m (default: the first truth record); "
                     "north/east/down-only trajectories (TUM, traj.txt) must be in this frame");
      sub.add_flag("--force", o->force, "Overwrite existing --json / --series files");
      return [o]() { return run(*o); };
    });

}  // namespace
