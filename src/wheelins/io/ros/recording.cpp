// What the three readers share: type names, times, opening a recording by its kind,
// and the ROS 2 MCAP reader on top of io/ros/mcap.hpp.
#include <algorithm>
#include <cstring>
#include <fstream>
#include <map>

#include "wheelins/io/ros/cdr.hpp"
#include "wheelins/io/ros/mcap.hpp"
#include "wheelins/io/ros/messages.hpp"
#include "wheelins/nav/types.hpp"

namespace wheelins::ros {
namespace fs = std::filesystem;

double seconds_from_ns(std::int64_t ns) { return static_cast<double>(ns) / 1e9; }

namespace {

/// ROS 2 MCAP: profile "ros2", schemas "pkg/msg/Name" (encoding ros2msg), messages
/// "cdr". The topics are not known before the data are read (the summary is optional),
/// so the files are scanned once for their channels and counts, then read again.
class McapBag final : public RecordingReader {
 public:
  explicit McapBag(std::vector<fs::path> files) : files_(std::move(files)) {
    std::map<std::string, std::size_t> by_name;
    for (const auto& f : files_) {
      McapReader r(f);
      McapMessage m;
      auto topic_of = [&](std::uint16_t channel) {
        const McapChannel& ch = r.channels().at(channel);
        std::string type;
        if (auto s = r.schemas().find(ch.schema_id); s != r.schemas().end()) type = s->second.name;
        auto [it, fresh] = by_name.emplace(ch.topic, topics_.size());
        if (fresh) {
          TopicInfo t;
          t.name = ch.topic;
          t.type = type;
          t.kind = message_kind(type);
          topics_.push_back(t);
          encodings_.push_back(ch.message_encoding);
        } else if (topics_[it->second].type != type) {
          throw InputError(r.name() + ": topic '" + ch.topic + "' is recorded with two types, '" +
                           topics_[it->second].type + "' and '" + type + "'");
        }
        return it->second;
      };
      std::map<std::uint16_t, std::size_t> seen;
      while (r.next(m)) {
        auto it = seen.find(m.channel);
        if (it == seen.end()) it = seen.emplace(m.channel, topic_of(m.channel)).first;
        ++topics_[it->second].count;
      }
      for (const auto& [id, ch] : r.channels())
        if (!seen.count(id)) topic_of(id);  // channels without messages are listed too
    }
    counts_.assign(topics_.size(), 0);
    wanted_.assign(topics_.size(), true);
  }

  const std::vector<TopicInfo>& topics() const override { return topics_; }
  std::string format() const override { return "ROS 2 MCAP"; }
  void select(const std::vector<bool>& wanted) override {
    wanted_ = wanted;
    for (std::size_t i = 0; i < topics_.size(); ++i)
      if (wanted_[i] && encodings_[i] != "cdr")
        throw InputError("'" + files_.front().string() + "': topic '" + topics_[i].name +
                         "' has message encoding '" + encodings_[i] + "', not cdr");
  }

  bool next(Message& out) override {
    for (;;) {
      if (!reader_) {
        if (file_ >= files_.size()) return false;
        reader_ = std::make_unique<McapReader>(files_[file_]);
        topic_of_.clear();
      }
      McapMessage m;
      bool more;
      try {
        more = reader_->next(m);
      } catch (const InputError& e) {
        std::string msg = e.what();
        if (last_topic_ < topics_.size())
          msg += " (after message " + std::to_string(counts_[last_topic_] - 1) + " of topic '" +
                 topics_[last_topic_].name + "')";
        throw InputError(msg);
      }
      if (!more) {
        reader_.reset();
        ++file_;
        continue;
      }
      auto it = topic_of_.find(m.channel);
      if (it == topic_of_.end()) {
        const std::string& name = reader_->channels().at(m.channel).topic;
        std::size_t t = 0;
        while (t < topics_.size() && topics_[t].name != name) ++t;
        it = topic_of_.emplace(m.channel, t).first;
      }
      const std::size_t t = it->second;
      if (t >= topics_.size() || !wanted_[t]) continue;
      out.topic = t;
      out.index = counts_[t]++;
      out.receive_ns = static_cast<std::int64_t>(m.log_time);
      last_topic_ = t;
      if (topics_[t].kind == MessageKind::kOther)
        throw InputError(reader_->name() + ": topic '" + topics_[t].name + "' has type '" + topics_[t].type +
                         "', which wheelins cannot read");
      try {
        decode_cdr(topics_[t].kind, m.data, m.size, out);
      } catch (const CdrError& e) {
        throw InputError(reader_->name() + ": topic '" + topics_[t].name + "' (" + topics_[t].type +
                         "), message " + std::to_string(out.index) + " (0-based, record at byte " +
                         std::to_string(m.offset) + "): " + e.what());
      }
      return true;
    }
  }

 private:
  std::vector<fs::path> files_;
  std::vector<TopicInfo> topics_;
  std::vector<std::string> encodings_;
  std::vector<std::uint64_t> counts_;
  std::vector<bool> wanted_;
  std::unique_ptr<McapReader> reader_;
  std::map<std::uint16_t, std::size_t> topic_of_;
  std::size_t file_ = 0;
  std::size_t last_topic_ = static_cast<std::size_t>(-1);
};

std::string lower_extension(const fs::path& p) {
  std::string e = p.extension().string();
  std::transform(e.begin(), e.end(), e.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return e;
}

std::string head_bytes(const fs::path& p, std::size_t n) {
  std::ifstream in(p, std::ios::binary);
  std::string s(n, '\0');
  in.read(s.data(), static_cast<std::streamsize>(n));
  s.resize(static_cast<std::size_t>(in.gcount()));
  return s;
}

}  // namespace

std::unique_ptr<RecordingReader> open_ros2_mcap(const std::vector<fs::path>& files) {
  return std::make_unique<McapBag>(files);
}

std::unique_ptr<RecordingReader> open_recording(const fs::path& path) {
  const std::string q = "'" + path.string() + "'";
  std::error_code ec;
  if (!fs::exists(path, ec)) throw InputError(q + ": not found");
  if (fs::is_directory(path, ec)) {
    // A ROS 2 bag directory: metadata.yaml and the storage files (split bags in name order).
    std::vector<fs::path> db3, mcap;
    for (const auto& e : fs::directory_iterator(path, ec)) {
      const std::string ext = lower_extension(e.path());
      if (ext == ".db3") db3.push_back(e.path());
      if (ext == ".mcap") mcap.push_back(e.path());
    }
    std::sort(db3.begin(), db3.end());
    std::sort(mcap.begin(), mcap.end());
    if (!db3.empty() && !mcap.empty())
      throw InputError(q + ": holds both .db3 and .mcap files; name the one to import");
    if (!db3.empty()) return open_ros2_db3(db3);
    if (!mcap.empty()) return open_ros2_mcap(mcap);
    throw InputError(q + ": a directory without .db3 or .mcap files (expected a ROS 2 bag directory, "
                         "or give a .bag, .db3 or .mcap file)");
  }
  const std::string head = head_bytes(path, 16);
  if (head.rfind("#ROSBAG V2.0", 0) == 0) return open_ros1_bag(path);
  if (head.size() == 16 && std::memcmp(head.data(), "SQLite format 3", 16) == 0) return open_ros2_db3({path});
  if (head.rfind("\x89MCAP", 0) == 0) return open_ros2_mcap({path});
  const std::string ext = lower_extension(path);
  if (ext == ".bag") return open_ros1_bag(path);  // the library names what is wrong
  if (ext == ".db3") return open_ros2_db3({path});
  if (ext == ".mcap") return open_ros2_mcap({path});
  throw InputError(q + ": not a ROS recording (expected a ROS 1 .bag, a ROS 2 .db3 or .mcap file, "
                       "or a ROS 2 bag directory)");
}

}  // namespace wheelins::ros
