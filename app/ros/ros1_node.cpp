// The ROS 1 node (ros1_node.hpp), with roscpp. C++17.
#include "ros1_node.hpp"

#include <algorithm>
#include <chrono>
#include <exception>
#include <mutex>
#include <sstream>
#include <stdexcept>
#include <utility>

#include <diagnostic_msgs/DiagnosticArray.h>
#include <nav_msgs/Odometry.h>
#include <ros/callback_queue.h>
#include <ros/ros.h>
#include <sensor_msgs/Imu.h>
#include <tf2_msgs/TFMessage.h>

namespace wheelins::ros1 {

namespace {
double steady_now() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

std::string text_of(XmlRpc::XmlRpcValue& v) {
  switch (v.getType()) {
    case XmlRpc::XmlRpcValue::TypeBoolean: return static_cast<bool>(v) ? "true" : "false";
    case XmlRpc::XmlRpcValue::TypeInt: return std::to_string(static_cast<int>(v));
    case XmlRpc::XmlRpcValue::TypeDouble: {
      std::ostringstream s;
      s.precision(17);
      s << static_cast<double>(v);
      return s.str();
    }
    case XmlRpc::XmlRpcValue::TypeString: return static_cast<std::string>(v);
    case XmlRpc::XmlRpcValue::TypeArray: {
      std::string out;
      for (int i = 0; i < v.size(); ++i) out += (i ? "," : "") + text_of(v[i]);
      return out;
    }
    default: return v.toXml();
  }
}

void flatten(const std::string& prefix, XmlRpc::XmlRpcValue& v, std::map<std::string, std::string>& out) {
  if (v.getType() == XmlRpc::XmlRpcValue::TypeStruct) {
    for (auto it = v.begin(); it != v.end(); ++it) flatten(prefix.empty() ? it->first : prefix + "." + it->first, it->second, out);
    return;
  }
  out[prefix] = text_of(v);
}

template <class V>
void set_xyz(V& v, const double (&a)[3]) {
  v.x = a[0];
  v.y = a[1];
  v.z = a[2];
}

template <class V>
void get_xyz(const V& v, double (&a)[3]) {
  a[0] = v.x;
  a[1] = v.y;
  a[2] = v.z;
}

ros::Time stamp_of(double t) { return t > 0.0 ? ros::Time(t) : ros::Time(0, 0); }

void copy_covariance(const std::array<double, 36>& from, boost::array<double, 36>& to) {
  for (std::size_t k = 0; k < 36; ++k) to[k] = from[k];
}
/// A callback queue that calls each callback at once, on the thread that adds it: roscpp's
/// receive thread, right after it read a message (ros::CallbackQueueInterface, the interface
/// roscpp's subscriptions are given their queue through). The global queue would wake the
/// node's thread once per message: a thousand times a second with five IMUs at 200 Hz.
class ImmediateQueue final : public ros::CallbackQueueInterface {
 public:
  void addCallback(const ros::CallbackInterfacePtr& callback, uint64_t /*owner_id*/) override {
    // Each added callback is one message of one subscription; with a single caller the
    // subscription is never busy (TryAgain) and an Invalid one is simply dropped.
    if (callback->ready()) callback->call();
  }
  void removeByID(uint64_t /*owner_id*/) override {}
};

}  // namespace

class RosNode final : public Node {
 public:
  RosNode(const std::string& name, const std::vector<std::string>& ros_args, double wait);
  ~RosNode() override;
  std::map<std::string, std::string> private_parameters() const override;
  std::string name() const override;
  void start(const NodeSetup& setup, std::function<void(const ImuMessage&)> on_imu) override;
  void stop() override;
  bool spin(double timeout) override;
  void publish(const Odometry& odom) override;
  void publish(const std::vector<Diagnostic>& status, double stamp) override;
  std::vector<std::string> wrong_types() const override;

 private:
  struct Impl {
    std::unique_ptr<ros::NodeHandle> nh, pnh;
    std::vector<ros::Subscriber> subs;
    ros::Publisher odom, tf, diagnostics;
    NodeSetup setup;
    std::function<void(const ImuMessage&)> on_imu;
    ImmediateQueue immediate;
    std::mutex failure_mutex;
    std::exception_ptr failure;  ///< what on_imu threw (rethrown by spin())
  };
  std::unique_ptr<Impl> impl_;
};

RosNode::RosNode(const std::string& name, const std::vector<std::string>& ros_args, double wait) : impl_(new Impl) {
  std::vector<std::string> args{"wheelins"};
  args.insert(args.end(), ros_args.begin(), ros_args.end());
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  int argc = static_cast<int>(argv.size());
  // Signals stay the program's (Ctrl-C ends the run as the end of input does).
  ros::init(argc, argv.data(), name, ros::init_options::NoSigintHandler);
  const double until = steady_now() + wait;
  while (!ros::master::check()) {
    if (steady_now() > until)
      throw std::runtime_error("no ROS master answers at " + ros::master::getURI() + " (ROS_MASTER_URI) within " +
                               std::to_string(static_cast<int>(wait)) + " s: start roscore first");
    ros::WallDuration(0.2).sleep();
  }
  impl_->nh.reset(new ros::NodeHandle());
  impl_->pnh.reset(new ros::NodeHandle("~"));
}

RosNode::~RosNode() {
  stop();
  impl_->pnh.reset();
  impl_->nh.reset();
  ros::shutdown();
}

std::string RosNode::name() const { return ros::this_node::getName(); }

std::map<std::string, std::string> RosNode::private_parameters() const {
  std::map<std::string, std::string> out;
  std::vector<std::string> keys;
  impl_->pnh->getParamNames(keys);
  const std::string ns = ros::this_node::getName() + "/";
  for (const auto& k : keys) {
    if (k.rfind(ns, 0) != 0) continue;
    const std::string rest = k.substr(ns.size());
    if (rest.find('/') != std::string::npos) continue;  // a dictionary: read whole below
    XmlRpc::XmlRpcValue v;
    if (impl_->pnh->getParam(rest, v)) flatten(rest, v, out);
  }
  // Dictionaries show up as their leaves: read each top-level name once.
  for (const auto& k : keys) {
    if (k.rfind(ns, 0) != 0) continue;
    const std::string rest = k.substr(ns.size());
    const std::size_t slash = rest.find('/');
    if (slash == std::string::npos) continue;
    const std::string top = rest.substr(0, slash);
    XmlRpc::XmlRpcValue v;
    if (impl_->pnh->getParam(top, v)) flatten(top, v, out);
  }
  return out;
}

void RosNode::start(const NodeSetup& setup, std::function<void(const ImuMessage&)> on_imu) {
  Impl& m = *impl_;
  m.setup = setup;
  m.on_imu = std::move(on_imu);
  // Advertised first: a message is handled (and may publish) as soon as it is subscribed to.
  m.odom = m.nh->advertise<nav_msgs::Odometry>(setup.odom_topic, 100);
  if (setup.publish_tf) m.tf = m.nh->advertise<tf2_msgs::TFMessage>("/tf", 100);
  m.diagnostics = m.nh->advertise<diagnostic_msgs::DiagnosticArray>("/diagnostics", 10);
  for (std::size_t i = 0; i < setup.topics.size(); ++i) {
    const int module = static_cast<int>(i);
    using Event = ros::MessageEvent<const sensor_msgs::Imu>;
    boost::function<void(const Event&)> cb = [this, module](const Event& event) {
      const sensor_msgs::Imu::ConstPtr& msg = event.getConstMessage();
      ImuMessage s;
      // Arrival: when roscpp's transport received the message (its receipt time, on the system
      // clock), not when this thread got to it; on simulated time the callback's time.
      s.arrival = steady_now();
      if (ros::Time::isSystemTime()) s.arrival -= std::max(0.0, (ros::Time::now() - event.getReceiptTime()).toSec());
      s.module = module;
      s.seq = msg->header.seq;
      s.t = msg->header.stamp.toSec();
      s.frame_id = msg->header.frame_id;
      get_xyz(msg->angular_velocity, s.gyro);
      get_xyz(msg->linear_acceleration, s.accel);
      Impl& impl = *impl_;
      const std::lock_guard<std::mutex> lock(impl.failure_mutex);
      if (impl.failure) return;
      try {
        impl.on_imu(s);
      } catch (...) {
        impl.failure = std::current_exception();
      }
    };
    ros::SubscribeOptions so;
    so.initByFullCallbackType<const Event&>(setup.topics[i], static_cast<std::uint32_t>(setup.queue), cb);
    so.transport_hints = ros::TransportHints().tcpNoDelay();
    so.callback_queue = &m.immediate;
    m.subs.push_back(m.nh->subscribe(so));
  }
}

void RosNode::stop() {
  // roscpp's subscription waits for a message being handled (its callbacks mutex) before it
  // lets go of the callback.
  for (auto& sub : impl_->subs) sub.shutdown();
  impl_->subs.clear();
}

bool RosNode::spin(double timeout) {
  if (!ros::ok()) return false;
  ros::getGlobalCallbackQueue()->callAvailable(ros::WallDuration(timeout));
  {
    const std::lock_guard<std::mutex> lock(impl_->failure_mutex);
    if (impl_->failure) std::rethrow_exception(impl_->failure);
  }
  return ros::ok();
}

void RosNode::publish(const Odometry& o) {
  const Impl& m = *impl_;
  nav_msgs::Odometry msg;
  msg.header.stamp = stamp_of(o.t);
  msg.header.frame_id = m.setup.odom_frame;
  msg.child_frame_id = m.setup.base_frame;
  set_xyz(msg.pose.pose.position, o.position);
  msg.pose.pose.orientation.x = o.orientation[0];
  msg.pose.pose.orientation.y = o.orientation[1];
  msg.pose.pose.orientation.z = o.orientation[2];
  msg.pose.pose.orientation.w = o.orientation[3];
  copy_covariance(o.pose_covariance, msg.pose.covariance);
  set_xyz(msg.twist.twist.linear, o.linear);
  set_xyz(msg.twist.twist.angular, o.angular);
  copy_covariance(o.twist_covariance, msg.twist.covariance);
  m.odom.publish(msg);
  if (!m.setup.publish_tf) return;
  tf2_msgs::TFMessage tf;
  geometry_msgs::TransformStamped tr;
  tr.header = msg.header;
  tr.child_frame_id = m.setup.base_frame;
  set_xyz(tr.transform.translation, o.position);
  tr.transform.rotation = msg.pose.pose.orientation;
  tf.transforms.push_back(tr);
  m.tf.publish(tf);
}

void RosNode::publish(const std::vector<Diagnostic>& status, double stamp) {
  diagnostic_msgs::DiagnosticArray msg;
  msg.header.stamp = stamp > 0.0 ? ros::Time(stamp) : ros::Time::now();
  for (const auto& d : status) {
    diagnostic_msgs::DiagnosticStatus s;
    s.level = d.level;
    s.name = d.name;
    s.message = d.message;
    s.hardware_id = d.hardware_id;
    for (const auto& [k, v] : d.values) {
      diagnostic_msgs::KeyValue kv;
      kv.key = k;
      kv.value = v;
      s.values.push_back(kv);
    }
    msg.status.push_back(s);
  }
  impl_->diagnostics.publish(msg);
}

std::vector<std::string> RosNode::wrong_types() const {
  std::vector<std::string> out(impl_->setup.topics.size());
  ros::master::V_TopicInfo topics;
  if (!ros::master::getTopics(topics)) return out;
  for (std::size_t i = 0; i < out.size(); ++i) {
    const std::string resolved = ros::names::resolve(impl_->setup.topics[i]);
    for (const auto& info : topics)
      if (info.name == resolved && info.datatype != "sensor_msgs/Imu") out[i] = info.datatype;
  }
  return out;
}

}  // namespace wheelins::ros1

extern "C" __attribute__((visibility("default"))) wheelins::ros1::Node* wheelins_ros1_connect(
    const std::string& name, const std::vector<std::string>& ros_args, double wait, std::string& error) {
  try {
    return new wheelins::ros1::RosNode(name, ros_args, wait);
  } catch (const std::exception& e) {
    error = e.what();
  } catch (...) {
    error = "an unknown error";
  }
  return nullptr;
}
