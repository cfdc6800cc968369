// The experiment's plots (paper Section VI, Fig. 7-10), drawn with gnuplot.
//
// Every plot is written as its data (CSV with a header, under `plots/data/`) and a
// gnuplot script (`plots/NAME.gp`) that reads the data by relative path, so a user
// can restyle a plot and re-run it: `cd plots && gnuplot NAME.gp` writes NAME.png.
// The writer then runs gnuplot on each script (pngcairo terminal, 1200x800 PNG).
// gnuplot is a separate Debian package (gnuplot-nox); when it is not on PATH the
// data and scripts are still written and one warning says how to get the PNGs.
//
// Plots (only those whose runs exist in the result; a missing one is a warning):
//  * trajectory.png: truth path (east/north, equal scale) and the 1 Hz tracks of the
//    Dual Wheel-INS, Body/Wheel-INS and Triple INS figure runs and of the single
//    Wheel-INS on the left Wheel-IMU's chip of the Dual Wheel-INS run.
//  * fig7_dual_wheel.png, fig8_body_wheel.png, fig9_triple.png: horizontal position
//    error and heading error against time since the start of navigation, for the
//    configuration's figure run and its wheel subsystems as stand-alone single
//    Wheel-INS runs (there is no stand-alone Body-INS run: the plot says so).
//  * fig10_drift_rate.png: r_k = max error within k*100 m / (k*100 m) [%] against
//    k*100 m, one panel per configuration, one curve per run, labelled by its chips.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "wheelins/run/experiment.hpp"
#include "wheelins/io/diagnostics.hpp"
#include "wheelins/io/truth.hpp"
#include "wheelins/nav/earth.hpp"

namespace wheelins::eval {

struct PlotOptions {
  /// The gnuplot program (looked up on PATH when it has no '/').
  std::string gnuplot = "gnuplot";
  /// Run gnuplot on the scripts; false writes data and scripts only (no warning).
  bool render = true;
};

/// The plot scripts and images whose names do not depend on the runs (for a check
/// before a long experiment that nothing would be overwritten).
std::vector<std::filesystem::path> experiment_plot_targets(const std::filesystem::path& dir);

/// Writes the plots of `r` into `dir/plots/` (data in `dir/plots/data/`) and renders
/// them. `truth` and `frame` are the experiment's (the truth path of the trajectory
/// plot, mapped to local north/east in `frame`). Refuses (InputError, before writing
/// anything) to replace an existing file unless `overwrite`. Returns the files
/// written: data, scripts, and the PNGs gnuplot produced. gnuplot missing or failing
/// on a script is reported through `warn`, not thrown.
std::vector<std::filesystem::path> write_experiment_plots(const ExperimentResult& r,
                                                          const TruthData& truth,
                                                          const earth::LocalFrame& frame,
                                                          const std::filesystem::path& dir,
                                                          bool overwrite, const WarningSink& warn,
                                                          const PlotOptions& options = {});

/// Runs gnuplot on `dir/NAME.gp` for each name (in `dir`, so the scripts' relative data paths
/// work), each writing `dir/NAME.png` through `NAME.png.partial`. Returns the PNGs made;
/// gnuplot missing (one warning, with the command to draw them later) or failing on a script
/// is reported through `warn`.
std::vector<std::filesystem::path> render_gnuplot(const std::filesystem::path& dir,
                                                  const std::vector<std::string>& names,
                                                  const WarningSink& warn, const PlotOptions& options = {});

}  // namespace wheelins::eval
