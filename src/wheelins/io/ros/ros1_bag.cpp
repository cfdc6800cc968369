// ROS 1 bags through the ROS bag storage library (Debian librosbag-storage-dev) and
// the generated message headers (libsensor-msgs-dev, libnav-msgs-dev,
// libgeometry-msgs-dev, libtf2-msgs-dev). The library checks each connection's type
// and MD5 sum on instantiate<T>() and throws on truncated or malformed data; both
// become InputError naming the file, topic and message index.
//
// Compiled as C++17 in a target of its own: the ROS 1 message headers use
// std::allocator<void>::rebind, which C++20 removed.
#include <geometry_msgs/PoseStamped.h>
#include <nav_msgs/Odometry.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <sensor_msgs/Imu.h>
#include <tf2_msgs/TFMessage.h>

#include <map>
#include <optional>

#include "wheelins/io/ros/messages.hpp"
#include "wheelins/nav/types.hpp"

namespace wheelins::ros {
namespace {

Stamp stamp_of(const ::ros::Time& t) { return Stamp{static_cast<std::int64_t>(t.sec), t.nsec}; }

template <class P>
std::array<double, 3> xyz(const P& p) {
  return {p.x, p.y, p.z};
}
template <class Q>
std::array<double, 4> quat(const Q& q) {
  return {q.x, q.y, q.z, q.w};
}

class Ros1Bag final : public RecordingReader {
 public:
  explicit Ros1Bag(const std::filesystem::path& file) : file_(file) {
    try {
      bag_.open(file.string(), rosbag::bagmode::Read);
      rosbag::View all(bag_);
      std::map<std::string, std::size_t> by_name;
      for (const rosbag::ConnectionInfo* c : all.getConnections()) {
        auto [it, fresh] = by_name.emplace(c->topic, topics_.size());
        if (fresh) {
          TopicInfo t;
          t.name = c->topic;
          t.type = c->datatype;
          t.kind = message_kind(c->datatype);
          topics_.push_back(t);
        } else if (topics_[it->second].type != c->datatype) {
          throw InputError(where() + ": topic '" + c->topic + "' is recorded with two types, '" +
                           topics_[it->second].type + "' and '" + c->datatype + "'");
        }
      }
      for (auto& t : topics_) {
        rosbag::View one(bag_, rosbag::TopicQuery(t.name));
        t.count = one.size();
      }
    } catch (const rosbag::BagException& e) {
      throw InputError(where() + ": cannot read as a ROS 1 bag: " + e.what());
    }
    counts_.assign(topics_.size(), 0);
    wanted_.assign(topics_.size(), false);
  }

  const std::vector<TopicInfo>& topics() const override { return topics_; }
  std::string format() const override { return "ROS 1 bag"; }

  void select(const std::vector<bool>& wanted) override {
    wanted_ = wanted;
    std::vector<std::string> names;
    for (std::size_t i = 0; i < topics_.size(); ++i)
      if (wanted_[i]) names.push_back(topics_[i].name);
    index_.clear();
    for (std::size_t i = 0; i < topics_.size(); ++i) index_[topics_[i].name] = i;
    try {
      view_.emplace(bag_, rosbag::TopicQuery(names));
      it_ = view_->begin();
    } catch (const rosbag::BagException& e) {
      throw InputError(where() + ": cannot read as a ROS 1 bag: " + e.what());
    }
  }

  bool next(Message& out) override {
    if (!view_) select(wanted_);
    std::string topic_name = "?";
    std::uint64_t index = 0;
    try {
      if (it_ == view_->end()) return false;
      const rosbag::MessageInstance& m = *it_;
      topic_name = m.getTopic();
      const std::size_t ti = index_.at(topic_name);
      index = counts_[ti]++;
      out.topic = ti;
      out.index = index;
      out.receive_ns = stamp_of(m.getTime()).ns();
      switch (topics_[ti].kind) {
        case MessageKind::kImu: {
          auto p = m.instantiate<sensor_msgs::Imu>();
          if (!p) throw wrong_type(m);
          out.imu.stamp = stamp_of(p->header.stamp);
          out.imu.frame_id = p->header.frame_id;
          out.imu.orientation = quat(p->orientation);
          out.imu.gyro = xyz(p->angular_velocity);
          out.imu.accel = xyz(p->linear_acceleration);
          break;
        }
        case MessageKind::kOdometry: {
          auto p = m.instantiate<nav_msgs::Odometry>();
          if (!p) throw wrong_type(m);
          out.pose = PoseMessage{};
          out.pose.stamp = stamp_of(p->header.stamp);
          out.pose.frame_id = p->header.frame_id;
          out.pose.child_frame_id = p->child_frame_id;
          out.pose.position = xyz(p->pose.pose.position);
          out.pose.orientation = quat(p->pose.pose.orientation);
          out.pose.has_twist = true;
          out.pose.linear = xyz(p->twist.twist.linear);
          out.pose.angular = xyz(p->twist.twist.angular);
          break;
        }
        case MessageKind::kPoseStamped: {
          auto p = m.instantiate<geometry_msgs::PoseStamped>();
          if (!p) throw wrong_type(m);
          out.pose = PoseMessage{};
          out.pose.stamp = stamp_of(p->header.stamp);
          out.pose.frame_id = p->header.frame_id;
          out.pose.position = xyz(p->pose.position);
          out.pose.orientation = quat(p->pose.orientation);
          break;
        }
        case MessageKind::kTf: {
          auto p = m.instantiate<tf2_msgs::TFMessage>();
          if (!p) throw wrong_type(m);
          out.tf.clear();
          for (const auto& t : p->transforms) {
            Transform x;
            x.stamp = stamp_of(t.header.stamp);
            x.parent = t.header.frame_id;
            x.child = t.child_frame_id;
            x.translation = xyz(t.transform.translation);
            x.rotation = quat(t.transform.rotation);
            out.tf.push_back(x);
          }
          break;
        }
        case MessageKind::kOther:
          throw InputError(where() + ": topic '" + topic_name + "' has type '" + topics_[ti].type +
                           "', which wheelins cannot read");
      }
      ++it_;
      return true;
    } catch (const InputError&) {
      throw;
    } catch (const std::exception& e) {
      // rosbag::BagException, ros::serialization::StreamOverrunException, ...
      throw InputError(where() + ": topic '" + topic_name + "', message " + std::to_string(index) +
                       " (0-based): cannot read (truncated or corrupt bag?): " + e.what());
    }
  }

 private:
  std::string where() const { return "'" + file_.string() + "'"; }
  InputError wrong_type(const rosbag::MessageInstance& m) const {
    return InputError(where() + ": topic '" + m.getTopic() + "': message type '" + m.getDataType() +
                      "' (MD5 " + m.getMD5Sum() + ") is not the " + m.getDataType() +
                      " definition this build knows");
  }

  std::filesystem::path file_;
  rosbag::Bag bag_;
  std::vector<TopicInfo> topics_;
  std::vector<std::uint64_t> counts_;
  std::vector<bool> wanted_;
  std::map<std::string, std::size_t> index_;
  std::optional<rosbag::View> view_;
  rosbag::View::iterator it_;
};

}  // namespace

std::unique_ptr<RecordingReader> open_ros1_bag(const std::filesystem::path& file) {
  return std::make_unique<Ros1Bag>(file);
}

}  // namespace wheelins::ros
