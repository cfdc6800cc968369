// The file formats of a navigation result (TrajectoryRecord, nav/trajectory_record.hpp):
// streaming writers and a validating reader.
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "wheelins/nav/earth.hpp"
#include "wheelins/nav/trajectory_record.hpp"

namespace wheelins {

// ---------------------------------------------------------------------------
// File formats.
//
// kCsv  (ours, written and read): one header row naming every column with its
//       unit, then one row per epoch. SI units except angles and lat/lon in
//       degrees, gyro biases in deg/h and scale factors in ppm:
//         t_s, north_m, east_m, down_m, lat_deg, lon_deg, h_m,
//         vn_m_s, ve_m_s, vd_m_s, roll_deg, pitch_deg, heading_deg,
//         north_std_m .. down_std_m, vn_std_m_s .. vd_std_m_s,
//         roll_std_deg, pitch_std_deg, heading_std_deg,
//         bg_{x,y,z}_deg_h, ba_{x,y,z}_m_s2, sg_{x,y,z}_ppm, sa_{x,y,z}_ppm,
//         and the same four groups with _std_ before the unit (bg_x_std_deg_h ...).
//       Time, position, lat/lon/h, velocity and attitude are written as the
//       shortest text that reads back to the identical double; the std and IMU
//       error columns with 9 significant digits. The reader finds columns by
//       header name (order free, unknown columns ignored); it needs t_s and either
//       lat_deg/lon_deg/h_m or north_m/east_m/down_m.
// kTum  (written and read): "t x y z qx qy qz qw" per line [m] in a local frame about a
//       geodetic origin, in one of two conventions (TumFrame):
//         ned: x north, y east, z down; q (Hamilton) rotates body vectors (x forward,
//              y right, z down) into NED: the vehicle attitude C_v^n. wheelins' default.
//         enu: x east, y north, z up; q rotates body vectors (x forward, y left, z up)
//              into ENU: ROS (REP 103) and evo.
//       '#' lines are comments. The writer starts with three of them, which the reader
//       understands: "# frame: ned|enu ...", "# origin: LAT_DEG LON_DEG H_M" (the local
//       frame's origin) and the column names. A file without a frame line is read in the
//       frame asked for, NED when none is asked for (and says so: frame_assumed); a frame
//       line that contradicts the one asked for is an error. Files written before the frame
//       line existed start "# t x(north) y(east) z(down)" and are read as NED.
// kKml  (written only): one LineString of lon,lat,h, decimated to at most one
//       point per `kml_min_interval` seconds and at most `kml_max_points` points.
// kWheelInsTraj (read only): the public Wheel-INS result file `traj.txt`
//       (i2Nav-WHU/Wheel-INS, src/main.cpp writeNavResult): whitespace-separated
//       text, 10 values per line:
//         t [s], pos x y z [m], vel x y z [m/s], roll pitch yaw [deg]
//       position/velocity are in the flat local NED frame that program navigates
//       in (origin: its initial position); the attitude is the Wheel-IMU's, whose yaw is
//       the vehicle heading + 90 deg (roll spins with the wheel). The reader sets
//       the vehicle heading to wrap(yaw - 90 deg) and leaves roll/pitch unknown.
//       The frame's origin and initial heading are Wheel-INS's own, so evaluate
//       these with alignment.
// ---------------------------------------------------------------------------

enum class TrajectoryFormat { kAuto, kCsv, kTum, kKml, kWheelInsTraj };

/// The convention of a TUM file (trajectory or truth): its axes and the body axes of its
/// quaternion (see kTum above).
enum class TumFrame {
  kEnu,  ///< x east, y north, z up; body x forward, y left, z up (ROS, evo)
  kNed,  ///< x north, y east, z down; body x forward, y right, z down (wheelins' default)
};

/// "enu" / "ned" <-> TumFrame (InputError for other names).
TumFrame tum_frame_from_name(const std::string& name);
const char* tum_frame_name(TumFrame frame);

/// A TUM pose in `frame` (position xyz, rotation C of its quaternion) as the NED position and
/// the vehicle attitude C_v^n (body forward/right/down into NED), and back.
void tum_pose_to_ned(TumFrame frame, const Vec3& xyz, const Mat3& C, Vec3& p_ned, Mat3& C_vn);
void tum_pose_from_ned(TumFrame frame, const Vec3& p_ned, const Mat3& C_vn, Vec3& xyz, Mat3& C);

/// What the comment lines at the top of a TUM file (before its first record) say: the
/// "# frame: ned|enu" and "# origin: LAT_DEG LON_DEG H_M" lines the writer puts there (a
/// first line "# t x(north) y(east) z(down) ..." of an older wheelins file counts as ned).
/// A frame or origin line that cannot be read is an InputError naming the line.
struct TumHeader {
  std::optional<TumFrame> frame{};
  std::size_t frame_line = 0;  ///< 1-based
  std::optional<earth::Geodetic> origin{};
};
TumHeader read_tum_header(const std::filesystem::path& file);

/// "auto", "csv", "tum", "kml", "wheelins-traj" <-> TrajectoryFormat.
TrajectoryFormat trajectory_format_from_name(const std::string& name);
const char* trajectory_format_name(TrajectoryFormat format);

/// Streaming writer of one trajectory file. Output goes to `file.partial` and is
/// renamed into place by commit(); without commit() nothing appears. An existing
/// file is refused (InputError) unless the writer was made with overwrite = true.
class TrajectoryWriter {
 public:
  virtual ~TrajectoryWriter() = default;
  virtual void write(const TrajectoryRecord& rec) = 0;
  virtual void commit() = 0;
  virtual std::uint64_t records() const = 0;  ///< records passed to write()
};

struct TrajectoryWriterOptions {
  bool overwrite = false;
  double kml_min_interval = 0.5;          ///< [s] between KML points
  std::size_t kml_max_points = 20000;     ///< hard cap on KML points (>= 2)
  std::string kml_name = "wheelins";      ///< KML document/placemark name
  TumFrame tum_frame = TumFrame::kNed;    ///< the TUM file's convention
  /// The origin of the records' p_inN, written into the TUM file's header (none: not written).
  std::optional<earth::Geodetic> origin{};
};

/// A writer for `format` (kCsv, kTum or kKml; others throw InputError).
std::unique_ptr<TrajectoryWriter> make_trajectory_writer(
    TrajectoryFormat format, const std::filesystem::path& file,
    const TrajectoryWriterOptions& options = {});

/// The CSV layout's column names in file order (its header row).
std::vector<std::string> trajectory_csv_header();
/// A record's values in the CSV's units (degrees, deg/h, ppm), in header order, at full
/// precision (the file rounds the std and IMU-error columns to 9 digits); `out` has room
/// for trajectory_csv_header().size() values.
void trajectory_csv_values(const TrajectoryRecord& r, double* out);

/// A trajectory read from a file, with what the format actually provided.
struct TrajectoryData {
  std::filesystem::path file;
  TrajectoryFormat format = TrajectoryFormat::kCsv;
  bool has_lla = false;       ///< lla is valid (p_inN also, in the writer's own frame)
  bool has_ned = false;       ///< p_inN is valid
  bool has_velocity = false;
  bool has_roll_pitch = false;
  bool has_heading = false;   ///< rpy.z() is the vehicle heading
  bool has_pos_std = false;   ///< p_std is valid
  /// TUM: the frame the file was read in (p_inN and rpy are converted to NED / C_v^n), and
  /// whether it was assumed (no frame line in the file and none asked for).
  TumFrame tum_frame = TumFrame::kNed;
  bool frame_assumed = false;
  /// TUM: the origin of p_inN from the file's "# origin:" line.
  std::optional<earth::Geodetic> origin{};
  std::vector<TrajectoryRecord> records;
};

struct TrajectoryReadOptions {
  /// TUM: the file's frame. Unset: the file's frame line, else NED (frame_assumed).
  std::optional<TumFrame> tum_frame{};
};

/// Guesses the format from the extension and the first non-comment line:
/// .csv or a header with letters and commas -> kCsv; 8 numbers -> kTum;
/// 10 numbers -> kWheelInsTraj; .kml -> InputError (output only).
TrajectoryFormat detect_trajectory_format(const std::filesystem::path& file);

/// Reads a trajectory; validates (finite time/position, strictly increasing time,
/// the expected number of columns) and throws InputError naming the file and the
/// line (1-based) of the first problem.
TrajectoryData read_trajectory(const std::filesystem::path& file,
                               TrajectoryFormat format = TrajectoryFormat::kAuto,
                               const TrajectoryReadOptions& options = {});

}  // namespace wheelins
