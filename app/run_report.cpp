// The evaluation printout shared by `run` and `odometry` (run_report.hpp).
#include "run_report.hpp"

#include <cmath>
#include <cstdio>

#include "wheelins/nav/types.hpp"

namespace wheelins {

void print_evaluation(const eval::EvalResult& e, const std::string& truth_file, double t_start, double t_end,
                      bool distributed_multi) {
  const double nav_s = t_end - t_start;
    std::printf("\nagainst the truth (%s):\n", truth_file.c_str());
    std::printf("  evaluated           %10.1f s of the %.1f s navigated (%zu truth epochs)\n",
                e.duration, nav_s, e.epochs);
    std::printf("  distance            %10.1f m\n", e.distance);
    if (e.drift_curve.empty())
      std::printf("  drift rate                 n/a (%.1f m travelled, shorter than one l = %.0f m "
                  "segment)\n", e.distance, e.segment_length);
    else
      std::printf("  drift rate          %10.3f %% of distance (l = %.0f m)\n", 100.0 * e.drift_rate,
                  e.segment_length);
    std::printf("  final error         %10.3f %% of distance (%.2f m)\n", 100.0 * e.final_error_ratio, e.final_error);
    if (e.has_heading)
      std::printf("  heading RMSE        %10.3f deg%s\n", e.heading_rmse / kDeg,
                  e.heading_source == "course" ? " (against the truth's course where it moves)" : "");
    std::printf("  max / final error   %6.2f / %.2f m\n", e.max_error, e.final_error);
    if (e.aligned && e.align_start > 0.0)
      std::printf("  start aligned       over the truth's first %.0f m: rotation %.3f deg (fit residual %.3f m)\n",
                  e.align_start, e.align_yaw / kDeg, e.align_residual);
    if (e.has_sigma)
      std::printf("  within 3 sigma      %10.1f %% of epochs (mean NEES %.2f, 2 if consistent)\n",
                  100.0 * e.within_3sigma, e.mean_nees);
    if (const std::string w = eval::sigma_warning(e); !w.empty())
      std::fprintf(stderr, "warning: %s%s\n", w.c_str(),
                   distributed_multi
                       ? ": the distributed filter fuses the position constraint into each subsystem as "
                         "if the others' reference point were independent of it, so its covariances "
                         "shrink at every constraint update; --centralized carries the correlation and "
                         "reports consistent figures (docs/filter.md section 9)"
                       : "");
    // The figures hold for the part of the run the truth covers: said when it is not all.
    if (e.duration < 0.95 * nav_s - 1.0)
      std::fprintf(stderr,
                   "warning: %s: the evaluation covers %.1f s (t %.3f .. %.3f) of the %.1f s navigated "
                   "(%.3f .. %.3f): the truth is shorter than the data, has a gap or a clock jump "
                   "(%zu truth epochs outside the trajectory, %zu in its gaps); the figures are for "
                   "that part only\n",
                   truth_file.c_str(), e.duration, e.t_start, e.t_end, nav_s, t_start,
                   t_end, e.skipped_outside, e.skipped_gap);
}

}  // namespace wheelins
