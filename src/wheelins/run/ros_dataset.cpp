// A ROS recording into a dataset with a drafted manifest (ros_dataset.hpp).
#include "wheelins/run/ros_dataset.hpp"

#include "wheelins/io/manifest.hpp"
#include "wheelins/io/text_util.hpp"
#include "wheelins/survey/draft.hpp"

namespace wheelins {
namespace fs = std::filesystem;

RosDatasetResult import_ros_dataset(const fs::path& recording, const fs::path& out_dir, const RosDatasetOptions& o) {
  RosDatasetResult r;
  survey::DraftOptions dopt;
  if (!o.vehicle_type.empty()) {
    dopt.vehicle = survey::vehicle_type(o.vehicle_type);
    dopt.vehicle_type_given = true;
  }
  // A vehicle manifest is read (and refused) before anything is written.
  if (o.vehicle) dopt.vehicle_from = load_manifest(*o.vehicle, o.import.warn);
  r.import = ros::import_recording(recording, out_dir, o.import);
  const ros::ImportResult& im = r.import;
  r.manifest_file = out_dir / "manifest.yaml";
  try {
    const ManifestDraft first = draft_manifest(out_dir, r.manifest_file);
    dopt.name = recording.filename().string();
    dopt.source = fs::absolute(recording).lexically_normal().string() + " (" + im.format + ")";
    for (const auto& [module, p] : im.positions) dopt.known_positions[module] = {p.p_inV, p.chain};
    r.draft = survey::draft_from_files(first, dopt, &r.survey);
    ManifestDraft& d = r.draft;
    for (std::size_t k = 0; k < d.manifest.modules.size(); ++k)
      for (const auto& t : im.imu)
        if (t.module == d.manifest.modules[k].name) d.notes.comments["modules[" + std::to_string(k) + "]"] = "topic " + t.topic;
    d.todo.insert(d.todo.end(), im.todo.begin(), im.todo.end());
    if (!im.truth && !im.pose_topics.empty()) {
      std::string list;
      for (const auto& t : im.pose_topics) list += (list.empty() ? "" : ", ") + t;
      d.todo.push_back("no truth: the recording has " + list + "; if one is a reference (GNSS/INS, motion capture), "
                       "import again with --truth TOPIC (and --origin LAT,LON,H)");
    }
    std::erase_if(d.facts, [](const std::string& x) { return x.find(" layout: ") != std::string::npos; });
    d.facts.insert(d.facts.begin(), im.facts.begin(), im.facts.end());
    save_manifest(d.manifest, r.manifest_file, d.notes);
  } catch (...) {
    std::error_code ec;
    for (const auto& t : im.imu) fs::remove(t.file, ec);
    if (im.odometer) fs::remove(im.odometer->file, ec);
    if (im.truth) fs::remove(im.truth->file, ec);
    throw;
  }
  if (o.import.warn && !r.draft.todo.empty())
    o.import.warn(io_detail::quote(r.manifest_file) + ": " + std::to_string(r.draft.todo.size()) +
                  " items are placeholders or unknown (marked TODO): measure or check them before trusting results");
  return r;
}

}  // namespace wheelins
