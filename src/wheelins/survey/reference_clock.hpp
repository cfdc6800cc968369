// The clock of a reference trajectory (a GNSS track) against the IMUs': its time unit and
// offset from the data, by the speed it shows against the wheels' (a vehicle's speed is the
// one signal both see). A track whose times are not in seconds (a column in tenths of a
// second, milliseconds) is found by trying the time scales 10^k (k = -3..3): only the right
// one makes the track's speed follow the wheels'.
#pragma once

#include <string>
#include <vector>

#include "wheelins/io/truth.hpp"
#include "wheelins/survey/dataset.hpp"

namespace wheelins::survey {

struct ReferenceClockFit {
  bool found = false;
  double scale = 1.0;    ///< seconds per unit of the track's time column
  double offset = 0.0;   ///< [s] IMU (common) clock = scale * track time + offset
  double sigma = 0.0;    ///< 1 sigma of the offset [s]
  double correlation = 0.0;
  std::vector<std::string> notes;
};

/// `track`: the reference's records with their times as read (unscaled); `series` and
/// `survey` as survey_series() saw them. Needs at least one wheel whose way forward is clear.
ReferenceClockFit fit_reference_clock(const std::vector<TruthRecord>& track, const std::vector<Series>& series,
                                      const DatasetSurvey& survey, const ClockOptions& options = {});

/// The vehicle's speed in wheel turns per second [rad/s] on the common clock: the mean of the
/// unsteered wheels whose way forward is clear (forward positive); empty without one.
Signal wheel_speed_signal(const std::vector<Series>& series, const DatasetSurvey& survey);

}  // namespace wheelins::survey
