// wheelins import (import.hpp): the topics chosen and checked, each message validated and
// converted (IMU files, truth, odometer speed), the module positions from /tf_static, the
// files staged and moved into place together.
#include "wheelins/io/ros/import.hpp"

#include <cctype>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <memory>

#include "wheelins/io/atomic_file.hpp"
#include "wheelins/io/imu_file.hpp"
#include "wheelins/io/odometer.hpp"
#include "wheelins/io/ros/messages.hpp"
#include "wheelins/io/text_util.hpp"
#include "wheelins/io/truth.hpp"

namespace wheelins::ros {
namespace fs = std::filesystem;
using io_detail::format_double;
using io_detail::quote;

std::string module_name_for_topic(const std::string& topic) {
  std::string s = topic;
  while (!s.empty() && s.front() == '/') s.erase(s.begin());
  for (char& c : s)
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-')) c = '_';
  return s.empty() ? "imu" : s;
}

namespace {

// Frame conventions: ENU world / FLU body (REP 103) to the NED / FRD frames of the truth
// file (math/rotation.hpp: both maps are their own inverses).
const Mat3 kEnuToNed = enu_ned_swap();
const Mat3 kFrdToFlu = frd_flu_swap();

struct Track {
  std::string topic, kind_text;
  std::int64_t prev_ns = 0;
  bool started = false;
};

class Importer {
 public:
  Importer(const fs::path& rec, const fs::path& out, const ImportOptions& o)
      : rec_(rec), out_(out), o_(o), reader_(open_recording(rec)) {}

  ImportResult run();

 private:
  std::string at(const Message& m) const {
    return quote(rec_) + ": topic '" + topics()[m.topic].name + "', message " + std::to_string(m.index) +
           " (0-based)";
  }
  const std::vector<TopicInfo>& topics() const { return reader_->topics(); }
  std::size_t find_topic(const std::string& name, const char* option) const;
  /// The message's time [ns]: the header stamp (a zero stamp is an error) or the receive time;
  /// it must be after the previous one of its topic.
  std::int64_t time_of(const Message& m, const Stamp& stamp, Track& tr) const;
  void finite(const Message& m, const std::array<double, 3>& v, const char* field) const;
  void finite4(const Message& m, const std::array<double, 4>& v, const char* field) const;
  std::vector<TruthRecord> truth_records(std::vector<std::pair<double, PoseMessage>>& poses,
                                         ImportResult& res) const;
  void apply_tf(ImportResult& res, const std::vector<Transform>& tf) const;

  fs::path rec_, out_;
  ImportOptions o_;
  std::unique_ptr<RecordingReader> reader_;
};

std::size_t Importer::find_topic(const std::string& name, const char* option) const {
  for (std::size_t i = 0; i < topics().size(); ++i)
    if (topics()[i].name == name) return i;
  std::string list;
  for (const auto& t : topics()) list += (list.empty() ? "" : ", ") + t.name + " (" + t.type + ")";
  throw InputError(quote(rec_) + ": " + option + " '" + name + "': no such topic; the recording has: " +
                   (list.empty() ? std::string("no topics") : list));
}

std::int64_t Importer::time_of(const Message& m, const Stamp& stamp, Track& tr) const {
  std::int64_t ns;
  if (o_.receive_time) {
    ns = m.receive_ns;
  } else {
    if (stamp.zero())
      throw InputError(at(m) + ": header stamp is zero (the publisher did not set it); "
                               "--receive-time takes the recorder's receive times instead");
    ns = stamp.ns();
  }
  if (tr.started && ns <= tr.prev_ns)
    throw InputError(at(m) + ": " + (o_.receive_time ? "receive time " : "header stamp ") +
                     format_double(seconds_from_ns(ns)) + " s " +
                     (ns == tr.prev_ns ? "repeats" : "goes back from") + " the previous message's " +
                     format_double(seconds_from_ns(tr.prev_ns)) +
                     " s (times must increase within a topic)");
  tr.started = true;
  tr.prev_ns = ns;
  return ns;
}

void Importer::finite(const Message& m, const std::array<double, 3>& v, const char* field) const {
  static const char* const axis[3] = {"x", "y", "z"};
  for (int i = 0; i < 3; ++i)
    if (!std::isfinite(v[i]))
      throw InputError(at(m) + ": " + field + "." + axis[i] + " is " + (std::isnan(v[i]) ? "NaN" : "infinite"));
}

void Importer::finite4(const Message& m, const std::array<double, 4>& v, const char* field) const {
  static const char* const axis[4] = {"x", "y", "z", "w"};
  for (int i = 0; i < 4; ++i)
    if (!std::isfinite(v[i]))
      throw InputError(at(m) + ": " + field + "." + axis[i] + " is " + (std::isnan(v[i]) ? "NaN" : "infinite"));
}

std::vector<TruthRecord> Importer::truth_records(std::vector<std::pair<double, PoseMessage>>& poses,
                                                 ImportResult& res) const {
  const earth::Geodetic origin = o_.origin.value_or(earth::Geodetic{});
  const earth::LocalFrame frame(origin);
  const bool enu = o_.convention == PoseConvention::kEnuFlu;
  std::vector<TruthRecord> out(poses.size());
  std::vector<Vec3> p_ned(poses.size());
  bool twist = true;
  for (std::size_t k = 0; k < poses.size(); ++k) {
    const PoseMessage& m = poses[k].second;
    const Vec3 p(m.position[0], m.position[1], m.position[2]);
    Quat q(m.orientation[3], m.orientation[0], m.orientation[1], m.orientation[2]);
    if (std::abs(q.norm() - 1.0) > 1e-3)
      throw InputError(quote(rec_) + ": topic '" + o_.truth_topic + "', message " + std::to_string(k) +
                       " (0-based): orientation is not a unit quaternion (norm " + format_double(q.norm()) + ")");
    q.normalize();
    const Mat3 C = q.toRotationMatrix();  // body -> world
    const Mat3 C_bn = enu ? Mat3(kEnuToNed * C * kFrdToFlu) : C;
    p_ned[k] = enu ? Vec3(kEnuToNed * p) : p;
    TruthRecord& r = out[k];
    r.t = poses[k].first;
    r.lla = frame.geodetic_from_ned(p_ned[k]);
    r.rpy = euler_from_dcm(C_bn);
    twist = twist && m.has_twist;
    if (m.has_twist) {
      const Vec3 v_child(m.linear[0], m.linear[1], m.linear[2]);  // in the child (body) frame
      r.v_ned = enu ? Vec3(kEnuToNed * (C * v_child)) : Vec3(C * v_child);
    }
  }
  if (!twist) {
    // PoseStamped has no velocity: central differences of the positions (one-sided at the ends).
    for (std::size_t k = 0; k < out.size(); ++k) {
      const std::size_t a = k == 0 ? 0 : k - 1, b = k + 1 < out.size() ? k + 1 : k;
      out[k].v_ned = b > a ? Vec3((p_ned[b] - p_ned[a]) / (out[b].t - out[a].t)) : Vec3::Zero();
    }
    res.facts.push_back("truth velocity: central differences of the positions (the topic has no twist)");
  }
  if (!o_.origin) {
    res.todo.push_back("the truth was placed at the placeholder origin 0 deg, 0 deg, 0 m: give "
                             "--origin LAT,LON,H (the geodetic position of the truth frame's origin) and "
                             "import again (gravity and the earth rate depend on it)");
    if (o_.warn)
      o_.warn(quote(rec_) + ": no --origin given: the truth frame's origin is taken to be at 0 deg, 0 deg, 0 m "
                            "(a placeholder; gravity and the earth rate depend on the latitude)");
  }
  return out;
}

void Importer::apply_tf(ImportResult& res, const std::vector<Transform>& tf) const {
  std::map<std::string, const Transform*> parent_of;
  for (const auto& t : tf) parent_of[t.child] = &t;
  for (const auto& imu : res.imu) {
    if (imu.frame_id.empty()) continue;
    Vec3 p = Vec3::Zero();
    std::string f = imu.frame_id;
    bool found = f == o_.base_frame;
    for (int hops = 0; !found && hops < 64; ++hops) {
      auto it = parent_of.find(f);
      if (it == parent_of.end()) break;
      const Transform& t = *it->second;
      const Quat q(t.rotation[3], t.rotation[0], t.rotation[1], t.rotation[2]);
      const Vec3 tr(t.translation[0], t.translation[1], t.translation[2]);
      p = q.normalized() * p + tr;  // point in child -> point in parent
      f = t.parent;
      found = f == o_.base_frame;
    }
    if (!found) continue;
    // base_link is FLU (REP 103), the v-frame FRD.
    res.positions[imu.module] = TfPosition{kFrdToFlu * p, "/tf_static: " + o_.base_frame + " -> " + imu.frame_id};
    res.facts.push_back(imu.module + ": position from /tf_static (" + o_.base_frame + " -> " + imu.frame_id + ")");
  }
}

ImportResult Importer::run() {
  ImportResult res;
  res.format = reader_->format();
  const auto& ts = topics();

  // Which topics, as what.
  std::vector<TopicModule> imus = o_.topics;
  if (imus.empty()) {
    for (const auto& t : ts)
      if (t.kind == MessageKind::kImu) imus.push_back({module_name_for_topic(t.name), t.name});
    if (imus.empty()) {
      std::string list;
      for (const auto& t : ts) list += (list.empty() ? "" : ", ") + t.name + " (" + t.type + ")";
      throw InputError(quote(rec_) + ": no sensor_msgs/Imu topic (the recording has: " +
                       (list.empty() ? std::string("no topics") : list) + ")");
    }
  }
  std::vector<int> imu_of(ts.size(), -1);
  std::map<std::string, int> names;
  for (std::size_t k = 0; k < imus.size(); ++k) {
    const std::size_t i = find_topic(imus[k].topic, "--topic");
    if (ts[i].kind != MessageKind::kImu)
      throw InputError(quote(rec_) + ": topic '" + ts[i].name + "' has type '" + ts[i].type +
                       "', expected sensor_msgs/Imu");
    if (imu_of[i] >= 0) throw InputError(quote(rec_) + ": topic '" + ts[i].name + "' is given twice");
    if (imus[k].module.empty() || imus[k].module.find_first_of("/\\") != std::string::npos)
      throw InputError("--topic " + imus[k].module + "=" + imus[k].topic + ": a module name must be non-empty "
                       "and hold no '/'");
    if (!names.emplace(imus[k].module, static_cast<int>(k)).second)
      throw InputError("module name '" + imus[k].module + "' is given to two topics");
    imu_of[i] = static_cast<int>(k);
  }
  std::size_t odo = ts.size(), truth = ts.size(), tf = ts.size();
  if (!o_.odometry_topic.empty()) {
    odo = find_topic(o_.odometry_topic, "--odometry");
    if (ts[odo].kind != MessageKind::kOdometry)
      throw InputError(quote(rec_) + ": --odometry topic '" + ts[odo].name + "' has type '" + ts[odo].type +
                       "', expected nav_msgs/Odometry");
  }
  if (!o_.truth_topic.empty()) {
    truth = find_topic(o_.truth_topic, "--truth");
    if (ts[truth].kind != MessageKind::kOdometry && ts[truth].kind != MessageKind::kPoseStamped)
      throw InputError(quote(rec_) + ": --truth topic '" + ts[truth].name + "' has type '" + ts[truth].type +
                       "', expected nav_msgs/Odometry or geometry_msgs/PoseStamped");
  }
  for (std::size_t i = 0; i < ts.size(); ++i)
    if (ts[i].name == "/tf_static" && ts[i].kind == MessageKind::kTf) tf = i;

  // Where it goes: refuse to mix with other data unless asked.
  std::error_code ec;
  if (fs::exists(out_, ec) && !fs::is_directory(out_, ec))
    throw InputError(quote(out_) + ": is a file, expected the output directory");
  if (fs::is_directory(out_, ec))
    for (const auto& n : io_detail::sweep_stale_partials(out_))
      if (o_.warn) o_.warn(quote(out_ / n) + ": removed, the temporary file of an import that was killed");
  if (fs::is_directory(out_, ec) && !fs::is_empty(out_, ec) && !o_.force)
    throw InputError(quote(out_) + ": is not empty (use --force to write into it)");
  fs::create_directories(out_, ec);
  if (ec) throw InputError(quote(out_) + ": cannot create: " + ec.message());
  const fs::path manifest_file = out_ / "manifest.yaml";
  {
    // Every output checked before the first is written; none may be the recording.
    std::vector<OutputFile> outs{{manifest_file, "--out"}};
    if (odo < ts.size()) outs.push_back({out_ / "odo.bin", "--out"});
    if (truth < ts.size()) outs.push_back({out_ / "GINS.bin", "--out"});
    for (const auto& tm : imus) outs.push_back({out_ / (tm.module + "_imu.bin"), "--out"});
    check_output_files(outs, {{rec_, "the recording"}}, o_.force);
  }

  std::vector<std::unique_ptr<ImuFileWriter>> writers;
  for (const auto& tm : imus) {
    ImportedTopic it;
    it.module = tm.module;
    it.topic = tm.topic;
    it.file = out_ / (tm.module + "_imu.bin");
    writers.push_back(std::make_unique<ImuFileWriter>(it.file, SampleFormat::kRate, FileLayout::kBinary, o_.force));
    res.imu.push_back(it);
  }
  std::unique_ptr<OdoWriter> odo_writer;
  if (odo < ts.size()) {
    res.odometer = ImportedTopic{"", ts[odo].name, "", out_ / "odo.bin"};
    odo_writer = std::make_unique<OdoWriter>(res.odometer->file, FileLayout::kBinary, o_.force);
  }
  if (truth < ts.size()) {
    res.truth = ImportedTopic{"", ts[truth].name, "", out_ / "GINS.bin"};
    check_output_target(res.truth->file, o_.force);
  }

  // One pass over the messages.
  std::vector<bool> wanted(ts.size(), false);
  for (std::size_t i = 0; i < ts.size(); ++i) wanted[i] = imu_of[i] >= 0 || i == odo || i == truth || i == tf;
  reader_->select(wanted);
  std::vector<Track> tracks(ts.size());
  Track truth_track;  // its own: the truth topic may also be the --odometry topic
  std::vector<std::pair<double, PoseMessage>> poses;
  std::vector<Transform> transforms;
  std::uint64_t total = 0, done = 0;
  for (std::size_t i = 0; i < ts.size(); ++i)
    if (wanted[i]) total += ts[i].count;
  Message m;
  while (reader_->next(m)) {
    if (o_.progress && (++done & 4095) == 0) o_.progress(done, total);
    const std::size_t i = m.topic;
    if (imu_of[i] >= 0) {
      ImportedTopic& it = res.imu[static_cast<std::size_t>(imu_of[i])];
      const double t = seconds_from_ns(time_of(m, m.imu.stamp, tracks[i]));
      finite(m, m.imu.gyro, "angular_velocity");
      finite(m, m.imu.accel, "linear_acceleration");
      if (it.messages == 0) {
        it.frame_id = m.imu.frame_id;
        it.t_first = t;
      }
      it.t_last = t;
      ++it.messages;
      ImuRow row;
      row.t = t;
      row.gyro = Vec3(m.imu.gyro[0], m.imu.gyro[1], m.imu.gyro[2]);
      row.accel = Vec3(m.imu.accel[0], m.imu.accel[1], m.imu.accel[2]);
      writers[static_cast<std::size_t>(imu_of[i])]->write_row(row);
    }
    if (i == odo) {
      const double t = seconds_from_ns(time_of(m, m.pose.stamp, tracks[i]));
      finite(m, m.pose.linear, "twist.twist.linear");
      if (res.odometer->messages++ == 0) res.odometer->t_first = t;
      res.odometer->t_last = t;
      odo_writer->write(OdoSample{t, m.pose.linear[0]});
    }
    if (i == truth) {
      const std::int64_t ns = time_of(m, m.pose.stamp, truth_track);
      finite(m, m.pose.position, m.pose.has_twist ? "pose.pose.position" : "pose.position");
      finite4(m, m.pose.orientation, m.pose.has_twist ? "pose.pose.orientation" : "pose.orientation");
      if (m.pose.has_twist) finite(m, m.pose.linear, "twist.twist.linear");
      const double t = seconds_from_ns(ns);
      if (res.truth->messages++ == 0) res.truth->t_first = t;
      res.truth->t_last = t;
      poses.emplace_back(t, m.pose);
    }
    if (i == tf)
      for (const auto& x : m.tf) transforms.push_back(x);
  }
  for (const auto& it : res.imu)
    if (it.messages == 0) throw InputError(quote(rec_) + ": topic '" + it.topic + "' has no messages");

  std::unique_ptr<TruthWriter> truth_writer;
  if (res.truth) {
    if (poses.empty()) throw InputError(quote(rec_) + ": --truth topic '" + res.truth->topic + "' has no messages");
    truth_writer = std::make_unique<TruthWriter>(res.truth->file, o_.force);
    for (const auto& r : truth_records(poses, res)) truth_writer->write(r);
  }

  // Everything read and valid: the files appear together.
  for (auto& w : writers) w->commit();
  if (odo_writer) odo_writer->commit();
  if (truth_writer) truth_writer->commit();
  res.facts.insert(res.facts.begin(), std::to_string(res.imu.size()) + " IMU module(s) from " +
                                          std::to_string(res.imu.size()) + " sensor_msgs/Imu topic(s)");
  if (!transforms.empty()) apply_tf(res, transforms);
  for (std::size_t i = 0; i < ts.size(); ++i)
    if ((ts[i].kind == MessageKind::kOdometry || ts[i].kind == MessageKind::kPoseStamped) && i != truth && i != odo)
      res.pose_topics.push_back(ts[i].name + " (" + ts[i].type + ")");
  return res;
}

}  // namespace

ImportResult import_recording(const fs::path& recording, const fs::path& out_dir, const ImportOptions& options) {
  return Importer(recording, out_dir, options).run();
}

}  // namespace wheelins::ros
