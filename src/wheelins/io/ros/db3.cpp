// ROS 2 bags in the sqlite3 storage (rosbag2_storage_default_plugins, the default
// storage up to Humble): a database with the tables
//   topics(id INTEGER PRIMARY KEY, name TEXT, type TEXT, serialization_format TEXT,
//          offered_qos_profiles TEXT [, type_description_hash TEXT])
//   messages(id INTEGER PRIMARY KEY, topic_id INTEGER, timestamp INTEGER, data BLOB)
// (+ schema and metadata tables from Iron on). timestamp is the receive time in ns since
// the epoch; data is the CDR-serialised message (io/ros/cdr.hpp). Messages are read in
// (timestamp, id) order, as ros2 bag play does. Only the columns above are used, so the
// older (Foxy, Galactic) and newer schemas read alike.
#include <sqlite3.h>

#include <map>

#include "wheelins/io/ros/cdr.hpp"
#include "wheelins/io/ros/messages.hpp"
#include "wheelins/nav/types.hpp"

namespace wheelins::ros {
namespace {

/// Finalizes a statement when it goes out of scope (also on an exception).
struct Finalize {
  sqlite3_stmt* st;
  ~Finalize() {
    if (st) sqlite3_finalize(st);
  }
};

class Db3Bag final : public RecordingReader {
 public:
  explicit Db3Bag(std::vector<std::filesystem::path> files) : files_(std::move(files)) {
    try {
      read_topics();
    } catch (...) {
      close();  // the destructor does not run for a constructor that throws
      throw;
    }
    counts_.assign(topics_.size(), 0);
    wanted_.assign(topics_.size(), true);
  }
  ~Db3Bag() override { close(); }

  void read_topics() {
    std::map<std::string, std::size_t> by_name;
    for (std::size_t f = 0; f < files_.size(); ++f) {
      open(f);
      sqlite3_stmt* st = prepare("SELECT id, name, type, serialization_format FROM topics");
      Finalize guard{st};
      std::map<std::int64_t, std::size_t> ids;
      int rc;
      while ((rc = sqlite3_step(st)) == SQLITE_ROW) {
        const std::int64_t id = sqlite3_column_int64(st, 0);
        const std::string name = text(st, 1), type = text(st, 2), format = text(st, 3);
        auto [it, fresh] = by_name.emplace(name, topics_.size());
        if (fresh) {
          TopicInfo t;
          t.name = name;
          t.type = type;
          t.kind = message_kind(type);
          topics_.push_back(t);
          formats_.push_back(format);
        } else if (topics_[it->second].type != type) {
          throw InputError(where() + ": topic '" + name + "' is recorded with two types, '" +
                           topics_[it->second].type + "' and '" + type + "'");
        }
        ids[id] = it->second;
      }
      check(rc, st);
      sqlite3_finalize(guard.st);
      guard.st = nullptr;
      guard.st = st = prepare("SELECT topic_id, COUNT(*) FROM messages GROUP BY topic_id");
      while ((rc = sqlite3_step(st)) == SQLITE_ROW) {
        auto it = ids.find(sqlite3_column_int64(st, 0));
        if (it == ids.end())
          throw InputError(where() + ": table messages refers to topic_id " +
                           std::to_string(sqlite3_column_int64(st, 0)) + ", which table topics lacks");
        topics_[it->second].count += static_cast<std::uint64_t>(sqlite3_column_int64(st, 1));
      }
      check(rc, st);
      sqlite3_finalize(guard.st);  // before close(): a database with a live statement stays open
      guard.st = nullptr;
      topic_ids_.push_back(ids);
      close();
    }
  }

  const std::vector<TopicInfo>& topics() const override { return topics_; }
  std::string format() const override { return "ROS 2 sqlite3"; }
  void select(const std::vector<bool>& wanted) override {
    wanted_ = wanted;
    for (std::size_t i = 0; i < topics_.size(); ++i)
      if (wanted_[i] && formats_[i] != "cdr")
        throw InputError("'" + files_.front().string() + "': topic '" + topics_[i].name +
                         "' is serialised as '" + formats_[i] + "', not cdr");
  }

  bool next(Message& out) override {
    for (;;) {
      if (!stmt_) {
        if (file_ + 1 >= files_.size() && started_) return false;
        file_ = started_ ? file_ + 1 : 0;
        started_ = true;
        open(file_);
        std::string in;
        for (const auto& [id, t] : topic_ids_[file_])
          if (wanted_[t]) in += (in.empty() ? "" : ",") + std::to_string(id);
        if (in.empty()) {
          close();
          continue;
        }
        stmt_ = prepare("SELECT topic_id, timestamp, data FROM messages WHERE topic_id IN (" + in +
                        ") ORDER BY timestamp, id");
      }
      const int rc = sqlite3_step(stmt_);
      if (rc == SQLITE_DONE) {
        sqlite3_finalize(stmt_);
        stmt_ = nullptr;
        close();
        continue;
      }
      if (rc != SQLITE_ROW) check(rc, stmt_);
      const std::size_t t = topic_ids_[file_].at(sqlite3_column_int64(stmt_, 0));
      out.topic = t;
      out.index = counts_[t]++;
      out.receive_ns = sqlite3_column_int64(stmt_, 1);
      const auto* data = static_cast<const std::uint8_t*>(sqlite3_column_blob(stmt_, 2));
      const std::size_t size = static_cast<std::size_t>(sqlite3_column_bytes(stmt_, 2));
      last_topic_ = t;
      if (topics_[t].kind == MessageKind::kOther)
        throw InputError(where() + ": topic '" + topics_[t].name + "' has type '" + topics_[t].type +
                         "', which wheelins cannot read");
      try {
        decode_cdr(topics_[t].kind, data, size, out);
      } catch (const CdrError& e) {
        throw InputError(where() + ": topic '" + topics_[t].name + "' (" + topics_[t].type + "), message " +
                         std::to_string(out.index) + " (0-based): " + e.what());
      }
      return true;
    }
  }

 private:
  std::string where() const { return "'" + files_[file_].string() + "'"; }
  void open(std::size_t f) {
    file_ = f;
    if (sqlite3_open_v2(files_[f].c_str(), &db_, SQLITE_OPEN_READONLY, nullptr) != SQLITE_OK) {
      const std::string msg = db_ ? sqlite3_errmsg(db_) : "out of memory";
      close();
      throw InputError(where() + ": cannot open as a ROS 2 sqlite3 bag: " + msg);
    }
  }
  void close() {
    if (stmt_) sqlite3_finalize(stmt_);
    stmt_ = nullptr;
    if (db_) sqlite3_close(db_);
    db_ = nullptr;
  }
  sqlite3_stmt* prepare(const std::string& sql) {
    sqlite3_stmt* st = nullptr;
    if (sqlite3_prepare_v2(db_, sql.c_str(), -1, &st, nullptr) != SQLITE_OK)
      throw InputError(where() + ": cannot read as a ROS 2 sqlite3 bag: " + sqlite3_errmsg(db_));
    return st;
  }
  void check(int rc, sqlite3_stmt* st) {
    if (rc == SQLITE_DONE) return;
    std::string msg = where() + ": cannot read as a ROS 2 sqlite3 bag: " + sqlite3_errmsg(db_);
    if (last_topic_ < topics_.size())
      msg += " (after message " + std::to_string(counts_[last_topic_] - 1) + " of topic '" +
             topics_[last_topic_].name + "')";
    (void)st;  // finalized by its owner (close() for stmt_, a Finalize guard otherwise)
    throw InputError(msg);
  }
  static std::string text(sqlite3_stmt* st, int col) {
    const unsigned char* s = sqlite3_column_text(st, col);
    return s ? reinterpret_cast<const char*>(s) : "";
  }

  std::vector<std::filesystem::path> files_;
  std::vector<TopicInfo> topics_;
  std::vector<std::string> formats_;
  std::vector<std::map<std::int64_t, std::size_t>> topic_ids_;
  std::vector<std::uint64_t> counts_;
  std::vector<bool> wanted_;
  sqlite3* db_ = nullptr;
  sqlite3_stmt* stmt_ = nullptr;
  std::size_t file_ = 0;
  bool started_ = false;
  std::size_t last_topic_ = static_cast<std::size_t>(-1);
};

}  // namespace

std::unique_ptr<RecordingReader> open_ros2_db3(const std::vector<std::filesystem::path>& files) {
  return std::make_unique<Db3Bag>(files);
}

}  // namespace wheelins::ros
