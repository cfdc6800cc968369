// A dataset from a ROS recording (`wheelins import RECORDING`, docs/ros-import.md): the
// messages converted (io/ros/import.hpp), then the manifest drafted the way IMU files side
// by side are (survey/draft.hpp draft_from_files): every module's kind from whether it
// spins, its axle, clock and side from the data, the static period from every module's
// rest; the positions /tf_static states written as measured. What only the user can tell is
// listed, and so are the recording's pose topics when no --truth was given (one of them
// may be the reference). Everything appears together or nothing does.
#pragma once

#include <filesystem>
#include <optional>
#include <string>

#include "wheelins/io/manifest_draft.hpp"
#include "wheelins/io/ros/import.hpp"
#include "wheelins/survey/dataset.hpp"

namespace wheelins {

struct RosDatasetOptions {
  ros::ImportOptions import;
  std::string vehicle_type;                      ///< car | robot (empty: car, said so)
  std::optional<std::filesystem::path> vehicle;  ///< a calibrated manifest of the same vehicle
};

struct RosDatasetResult {
  ros::ImportResult import;
  survey::DatasetSurvey survey;
  ManifestDraft draft;
  std::filesystem::path manifest_file;
};

RosDatasetResult import_ros_dataset(const std::filesystem::path& recording, const std::filesystem::path& out_dir,
                                    const RosDatasetOptions& options);

}  // namespace wheelins
