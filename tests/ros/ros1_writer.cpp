// ROS 1 bags for the tests, written with the ROS bag storage library (C++17: the ROS 1
// message headers do not compile as C++20).
#include <geometry_msgs/PoseStamped.h>
#include <nav_msgs/Odometry.h>
#include <rosbag/bag.h>
#include <sensor_msgs/Imu.h>
#include <tf2_msgs/TFMessage.h>

#include <stdexcept>

#include "bag_writers.hpp"

namespace wheelins::test_ros {
namespace {
::ros::Time time_of(const ros::Stamp& s) {
  return ::ros::Time(static_cast<std::uint32_t>(s.sec), s.nsec);
}
::ros::Time time_ns(std::int64_t ns) {
  return ::ros::Time(static_cast<std::uint32_t>(ns / 1000000000), static_cast<std::uint32_t>(ns % 1000000000));
}
template <class V>
void set3(V& v, const std::array<double, 3>& a) {
  v.x = a[0];
  v.y = a[1];
  v.z = a[2];
}
template <class Q>
void set4(Q& q, const std::array<double, 4>& a) {
  q.x = a[0];
  q.y = a[1];
  q.z = a[2];
  q.w = a[3];
}
}  // namespace

void write_ros1_bag(const std::filesystem::path& file, const std::vector<OutMessage>& msgs,
                    const std::string& compression) {
  rosbag::Bag bag(file.string(), rosbag::bagmode::Write);
  if (compression == "lz4") bag.setCompression(rosbag::compression::LZ4);
  else if (compression == "bz2") bag.setCompression(rosbag::compression::BZ2);
  else if (compression != "none") throw std::invalid_argument("compression " + compression);
  for (const OutMessage& m : msgs) {
    const ::ros::Time when = time_ns(m.receive_ns);
    switch (m.kind) {
      case ros::MessageKind::kImu: {
        sensor_msgs::Imu x;
        x.header.stamp = time_of(m.imu.stamp);
        x.header.frame_id = m.imu.frame_id;
        set4(x.orientation, m.imu.orientation);
        set3(x.angular_velocity, m.imu.gyro);
        set3(x.linear_acceleration, m.imu.accel);
        bag.write(m.topic, when, x);
        break;
      }
      case ros::MessageKind::kOdometry: {
        nav_msgs::Odometry x;
        x.header.stamp = time_of(m.pose.stamp);
        x.header.frame_id = m.pose.frame_id;
        x.child_frame_id = m.pose.child_frame_id;
        set3(x.pose.pose.position, m.pose.position);
        set4(x.pose.pose.orientation, m.pose.orientation);
        set3(x.twist.twist.linear, m.pose.linear);
        set3(x.twist.twist.angular, m.pose.angular);
        bag.write(m.topic, when, x);
        break;
      }
      case ros::MessageKind::kPoseStamped: {
        geometry_msgs::PoseStamped x;
        x.header.stamp = time_of(m.pose.stamp);
        x.header.frame_id = m.pose.frame_id;
        set3(x.pose.position, m.pose.position);
        set4(x.pose.orientation, m.pose.orientation);
        bag.write(m.topic, when, x);
        break;
      }
      case ros::MessageKind::kTf: {
        tf2_msgs::TFMessage x;
        for (const auto& t : m.tf) {
          geometry_msgs::TransformStamped s;
          s.header.stamp = time_of(t.stamp);
          s.header.frame_id = t.parent;
          s.child_frame_id = t.child;
          set3(s.transform.translation, t.translation);
          set4(s.transform.rotation, t.rotation);
          x.transforms.push_back(s);
        }
        bag.write(m.topic, when, x);
        break;
      }
      case ros::MessageKind::kOther:
        throw std::invalid_argument("write_ros1_bag: kOther");
    }
  }
  bag.close();
}

}  // namespace wheelins::test_ros
