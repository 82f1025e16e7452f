#include "ros/bridge/ros_connection.hpp"

#include <ros/master.h>
#include <ros/ros.h>
#include <ros/xmlrpc_manager.h>

#include <chrono>
#include <mutex>
#include <thread>

#include "ros/bridge/message_conversions.hpp"
#include "scanner/common/error.hpp"

namespace uwscan::ros {
namespace {

template <typename Message>
std::string DataType() {
  return ::ros::message_traits::DataType<Message>::value();
}

std::string DataTypeOf(RosConnection::Kind kind) {
  switch (kind) {
    case RosConnection::Kind::kCloud:
      return DataType<sensor_msgs::PointCloud2>();
    case RosConnection::Kind::kPath:
      return DataType<nav_msgs::Path>();
    case RosConnection::Kind::kPose:
      return DataType<geometry_msgs::PoseWithCovarianceStamped>();
    case RosConnection::Kind::kPoseArray:
      return DataType<geometry_msgs::PoseArray>();
    case RosConnection::Kind::kMarkers:
      return DataType<visualization_msgs::MarkerArray>();
    case RosConnection::Kind::kTransforms:
      return DataType<tf2_msgs::TFMessage>();
  }
  return "";
}

// Registers `topic` again with the master as this node's; false when the master refused.
bool Register(const std::string& method, const std::string& topic, const std::string& datatype) {
  XmlRpc::XmlRpcValue args, result, payload;
  args[0] = ::ros::this_node::getName();
  args[1] = topic;
  args[2] = datatype;
  args[3] = ::ros::XMLRPCManager::instance()->getServerURI();
  return ::ros::master::execute(method, args, result, payload, false);
}

}  // namespace

struct RosConnection::Impl {
  struct Registration {
    std::string topic;  // resolved
    std::string datatype;
  };
  std::unique_ptr<::ros::NodeHandle> node;
  std::unique_ptr<::ros::NodeHandle> private_node;
  std::unique_ptr<::ros::AsyncSpinner> spinner;
  std::mutex mutex;  // publishers
  std::vector<::ros::Publisher> publishers;
  std::vector<::ros::Subscriber> subscribers;
  std::vector<Registration> published, subscribed;
  bool master_lost = false;
  int reregistrations = 0;
  std::function<void(std::exception_ptr)> on_error;  // set before Start

  template <typename RosMessage, typename Message>
  void Subscribe(const std::string& topic, int queue, std::function<void(Message&&)> callback) {
    auto handler = [this, topic,
                    callback = std::move(callback)](const boost::shared_ptr<const RosMessage>& m) {
      // An exception must not reach roscpp's spinner thread (it would end the process).
      try {
        callback(FromRos(*m));
      } catch (const std::exception& e) {
        if (on_error) on_error(std::make_exception_ptr(Error("topic " + topic + ": " + e.what())));
      }
    };
    subscribers.push_back(node->subscribe<RosMessage>(topic, static_cast<std::uint32_t>(queue),
                                                      handler, ::ros::VoidConstPtr(),
                                                      ::ros::TransportHints().tcpNoDelay()));
    subscribed.push_back({node->resolveName(topic), DataType<RosMessage>()});
  }

  template <typename RosMessage>
  ::ros::Publisher Advertise(const std::string& topic, bool latched) {
    return node->advertise<RosMessage>(topic, 100, latched);
  }

  template <typename Message>
  void Publish(int id, const Message& message) {
    auto ros_message = ToRos(message);
    std::lock_guard<std::mutex> lock(mutex);
    publishers.at(static_cast<std::size_t>(id)).publish(ros_message);
  }
};

RosConnection::RosConnection(const std::string& name, const std::vector<std::string>& arguments,
                             double master_wait_s)
    : impl_(std::make_unique<Impl>()) {
  std::vector<std::string> argv_strings = {"uwscan"};
  argv_strings.insert(argv_strings.end(), arguments.begin(), arguments.end());
  std::vector<char*> argv;
  for (std::string& s : argv_strings) argv.push_back(s.data());
  int argc = static_cast<int>(argv.size());
  ::ros::init(argc, argv.data(), name, ::ros::init_options::NoSigintHandler);
  const auto deadline =
      std::chrono::steady_clock::now() + std::chrono::duration<double>(master_wait_s);
  while (!::ros::master::check()) {
    if (std::chrono::steady_clock::now() >= deadline) {
      throw Error("no ROS master at " + ::ros::master::getURI() + " (waited " +
                  std::to_string(master_wait_s) + " s; start roscore, or set ROS_MASTER_URI)");
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  impl_->node = std::make_unique<::ros::NodeHandle>();
  impl_->private_node = std::make_unique<::ros::NodeHandle>("~");
}

RosConnection::~RosConnection() {
  if (impl_->spinner) impl_->spinner->stop();
  impl_->subscribers.clear();
  impl_->publishers.clear();
  impl_->private_node.reset();
  impl_->node.reset();
  ::ros::shutdown();
}

namespace {
template <typename T>
T GetParam(const ::ros::NodeHandle& node, const std::string& name, const T& fallback) {
  if (!node.hasParam(name)) return fallback;
  T value = fallback;
  if (!node.getParam(name, value)) {
    throw Error("parameter " + node.resolveName(name) + " has the wrong type");
  }
  return value;
}
}  // namespace

std::string RosConnection::Param(const std::string& name, const std::string& fallback) const {
  return GetParam(*impl_->private_node, name, fallback);
}
double RosConnection::Param(const std::string& name, double fallback) const {
  return GetParam(*impl_->private_node, name, fallback);
}
int RosConnection::Param(const std::string& name, int fallback) const {
  return GetParam(*impl_->private_node, name, fallback);
}
bool RosConnection::Param(const std::string& name, bool fallback) const {
  return GetParam(*impl_->private_node, name, fallback);
}

void RosConnection::SetErrorHandler(std::function<void(std::exception_ptr)> handler) {
  impl_->on_error = std::move(handler);
}

void RosConnection::SubscribeImages(const std::string& topic, int queue,
                                    std::function<void(ImageMessage&&)> callback) {
  impl_->Subscribe<sensor_msgs::Image>(topic, queue, std::move(callback));
}
void RosConnection::SubscribeOdometry(const std::string& topic, int queue,
                                      std::function<void(OdometryMessage&&)> callback) {
  impl_->Subscribe<nav_msgs::Odometry>(topic, queue, std::move(callback));
}
void RosConnection::SubscribeText(const std::string& topic,
                                  std::function<void(StringMessage&&)> callback) {
  impl_->Subscribe<std_msgs::String>(topic, 10, std::move(callback));
}
void RosConnection::SubscribeClouds(const std::string& topic, int queue,
                                    std::function<void(CloudMessage&&)> callback) {
  impl_->Subscribe<sensor_msgs::PointCloud2>(topic, queue, std::move(callback));
}
void RosConnection::SubscribeTransforms(
    const std::string& topic, int queue,
    std::function<void(std::vector<TransformMessage>&&)> callback) {
  impl_->Subscribe<tf2_msgs::TFMessage>(topic, queue, std::move(callback));
}

void RosConnection::Unsubscribe() {
  // Subscriber::shutdown removes the subscription's callbacks from the queue, waiting for one
  // being called.
  for (::ros::Subscriber& s : impl_->subscribers) s.shutdown();
  impl_->subscribers.clear();
  impl_->subscribed.clear();
}

int RosConnection::Advertise(const std::string& topic, Kind kind, bool latched) {
  ::ros::Publisher p;
  switch (kind) {
    case Kind::kCloud:
      p = impl_->Advertise<sensor_msgs::PointCloud2>(topic, latched);
      break;
    case Kind::kPath:
      p = impl_->Advertise<nav_msgs::Path>(topic, latched);
      break;
    case Kind::kPose:
      p = impl_->Advertise<geometry_msgs::PoseWithCovarianceStamped>(topic, latched);
      break;
    case Kind::kPoseArray:
      p = impl_->Advertise<geometry_msgs::PoseArray>(topic, latched);
      break;
    case Kind::kMarkers:
      p = impl_->Advertise<visualization_msgs::MarkerArray>(topic, latched);
      break;
    case Kind::kTransforms:
      p = impl_->Advertise<tf2_msgs::TFMessage>(topic, latched);
      break;
  }
  std::lock_guard<std::mutex> lock(impl_->mutex);
  impl_->publishers.push_back(p);
  impl_->published.push_back({impl_->node->resolveName(topic), DataTypeOf(kind)});
  return static_cast<int>(impl_->publishers.size()) - 1;
}

void RosConnection::Publish(int id, const CloudMessage& m) { impl_->Publish(id, m); }
void RosConnection::Publish(int id, const PathMessage& m) { impl_->Publish(id, m); }
void RosConnection::Publish(int id, const PoseMessage& m) { impl_->Publish(id, m); }
void RosConnection::Publish(int id, const PoseArrayMessage& m) { impl_->Publish(id, m); }
void RosConnection::Publish(int id, const std::vector<MarkerMessage>& m) { impl_->Publish(id, m); }
void RosConnection::Publish(int id, const std::vector<TransformMessage>& m) {
  impl_->Publish(id, m);
}

void RosConnection::Start(int threads) {
  impl_->spinner = std::make_unique<::ros::AsyncSpinner>(static_cast<std::uint32_t>(threads));
  impl_->spinner->start();
}

bool RosConnection::Ok() const { return ::ros::ok(); }

bool RosConnection::KeepRegistered() {
  if (!::ros::master::check()) {
    impl_->master_lost = true;
    return false;
  }
  if (!impl_->master_lost) return true;
  bool all = true;
  {
    std::lock_guard<std::mutex> lock(impl_->mutex);
    for (const Impl::Registration& r : impl_->published)
      all = Register("registerPublisher", r.topic, r.datatype) && all;
  }
  for (const Impl::Registration& r : impl_->subscribed)
    all = Register("registerSubscriber", r.topic, r.datatype) && all;
  if (all) {
    impl_->master_lost = false;
    ++impl_->reregistrations;
  }
  return true;
}

int RosConnection::reregistrations() const { return impl_->reregistrations; }

}  // namespace uwscan::ros
