#include "ros/node/inspection_node.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <deque>
#include <exception>
#include <memory>
#include <mutex>
#include <thread>
#include <tuple>

#include "mapping/inspection/camera_frames.hpp"
#include "mapping/inspection/camera_reader.hpp"
#include "mapping/slam/dive_mapping.hpp"
#include "mapping/slam/live_map.hpp"
#include "mapping/slam/mapper.hpp"
#include "ros/conversions/dive_description.hpp"
#include "ros/conversions/frame_image.hpp"
#include "ros/conversions/static_transforms.hpp"
#include "ros/node/inspection_outlet.hpp"
#include "scanner/common/error.hpp"
#include "scanner/common/option_checks.hpp"

namespace uwscan::ros {
namespace {

using inspection_detail::Clock;
using inspection_detail::Outlet;
using inspection_detail::SecondsSince;
using inspection_detail::UnixNow;

// The first failure of any callback thread, rethrown on the node's thread.
class Failure {
 public:
  void Set(std::exception_ptr e) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!failure_) failure_ = std::move(e);
  }
  bool IsSet() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return failure_ != nullptr;
  }
  void Rethrow() const {
    std::lock_guard<std::mutex> lock(mutex_);
    if (failure_) std::rethrow_exception(failure_);
  }

 private:
  mutable std::mutex mutex_;
  std::exception_ptr failure_;
};

// What the node learns from its latched topics before frames are taken: the scanner (dive
// description) and the camera's mount (/tf_static).
struct DiveSetup {
  mapping::DiveLogHeader header;
  double time_origin_s = 0.0;
  bool described = false;
  Eigen::Isometry3d T_V_C = Eigen::Isometry3d::Identity();
  std::string mount;
};

class SetupListener {
 public:
  SetupListener(RosConnection& ros, const InspectionNodeOptions& o, Failure& failure)
      : options_(o) {
    if (!o.header) {
      ros.SubscribeText(o.topics.dive, [this, &failure, topic = o.topics.dive](StringMessage&& m) {
        try {
          DiveDescription d = ParseDiveDescription(m.data, "topic " + topic);
          std::lock_guard<std::mutex> lock(mutex_);
          if (!description_) description_ = std::move(d);
        } catch (...) {
          failure.Set(std::current_exception());
        }
      });
    }
    ros.SubscribeTransforms(o.topics.tf_static, 100,
                            [this](std::vector<TransformMessage>&& transforms) {
                              std::lock_guard<std::mutex> lock(mutex_);
                              for (const TransformMessage& t : transforms) statics_.Add(t);
                            });
  }

  // Waits for the scanner, then for the mount (or gives up on it). Throws when the scanner
  // does not come in time.
  DiveSetup Wait(const Failure& failure, const std::function<bool()>& stop_requested) {
    DiveSetup setup;
    const Clock::time_point start = Clock::now();
    while (!options_.header && !Described()) {
      failure.Rethrow();
      if (stop_requested()) throw Error("stopped while waiting for the dive description");
      if (SecondsSince(start) > options_.description_wait_s) {
        throw Error("no dive description on " + options_.topics.dive + " within " +
                    std::to_string(options_.description_wait_s) +
                    " s: give the scanner (--scanner, or ~scanner)");
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    if (options_.header) {
      setup.header = *options_.header;
    } else {
      std::lock_guard<std::mutex> lock(mutex_);
      setup.header = description_->header;
      setup.time_origin_s = description_->time_origin_s;
      setup.described = true;
    }
    const Clock::time_point mount_start = Clock::now();
    std::optional<Eigen::Isometry3d> T_V_C;
    while (!(T_V_C = Mount()) && SecondsSince(mount_start) < options_.mount_wait_s &&
           !stop_requested()) {
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    const RosFrames& f = options_.frames;
    setup.T_V_C =
        MountInUwscanAxes(T_V_C.value_or(Eigen::Isometry3d::Identity()), options_.navigation.axes);
    setup.mount = T_V_C ? options_.topics.tf_static + " " + f.base_link + " -> " + f.camera
                        : "none on " + options_.topics.tf_static + " from " + f.base_link + " to " +
                              f.camera + ": the camera is taken at the vehicle's origin";
    return setup;
  }

 private:
  bool Described() {
    std::lock_guard<std::mutex> lock(mutex_);
    return description_.has_value();
  }
  std::optional<Eigen::Isometry3d> Mount() {
    std::lock_guard<std::mutex> lock(mutex_);
    return statics_.Find(options_.frames.base_link, options_.frames.camera);
  }

  const InspectionNodeOptions& options_;
  std::mutex mutex_;
  std::optional<DiveDescription> description_;
  StaticTransforms statics_;
};

// Frames and navigation from their topics into the inspection. Callbacks run on roscpp's
// spinner threads. Until Begin() (the scanner is not known yet) messages wait here, up to
// `capacity` frames; after Close() none reaches the inspection any more.
class Intake {
 public:
  Intake(const InspectionNodeOptions& o, Failure& failure)
      : options_(o), failure_(failure), capacity_(static_cast<std::size_t>(o.frame_queue)) {}

  void Begin(const DiveSetup& setup, mapping::LiveInspection& inspection) {
    std::scoped_lock lock(frames_mutex_, navigation_mutex_);
    decoder_.emplace(setup.header.scanner.camera().camera, options_.detector, options_.keep_images);
    time_origin_s_ = setup.time_origin_s;
    inspection_ = &inspection;
    for (OdometryMessage& m : pending_navigation_) AddNavigation(m);
    for (ImageMessage& m : pending_frames_) AddFrame(m);
    pending_navigation_.clear();
    pending_frames_.clear();
  }

  void OnImage(ImageMessage&& m) {
    std::lock_guard<std::mutex> lock(frames_mutex_);
    if (closed_) return;
    ++frames_;
    if (inspection_ != nullptr) {
      AddFrame(m);
    } else if (pending_frames_.size() < capacity_) {
      pending_frames_.push_back(std::move(m));
    } else {
      ++dropped_;
    }
  }

  // A frame read from the camera (CameraInput), on the camera's thread, after Begin().
  void OnCameraFrame(mapping::FrameRecord&& record,
                     const scanner::acquisition::AcquiredFrame& frame) {
    std::lock_guard<std::mutex> lock(frames_mutex_);
    if (closed_) return;
    ++frames_;
    try {
      mapping::InspectionFrame f = mapping::ToInspectionFrame(std::move(record), frame);
      if (first_receive_s_ == 0.0) first_receive_s_ = f.receive_time_s;
      last_receive_s_ = f.receive_time_s;
      inspection_->Push(std::move(f));
    } catch (...) {
      closed_ = true;
      failure_.Set(std::current_exception());
    }
  }

  void OnOdometry(OdometryMessage&& m) {
    std::lock_guard<std::mutex> lock(navigation_mutex_);
    if (closed_) return;
    if (inspection_ != nullptr) {
      AddNavigation(m);
    } else {
      pending_navigation_.push_back(std::move(m));
    }
  }

  void Close() {
    std::scoped_lock lock(frames_mutex_, navigation_mutex_);
    closed_ = true;
  }

  std::int64_t frames() const { return frames_.load(); }
  std::int64_t undecodable() const { return undecodable_.load(); }
  std::int64_t dropped() const { return dropped_.load(); }
  std::int64_t navigation() const { return navigation_.load(); }
  // From the first frame's arrival to the last one's, seconds (after Close()).
  double receive_span_s() const { return last_receive_s_ - first_receive_s_; }

 private:
  // With frames_mutex_ held.
  void AddFrame(const ImageMessage& m) {
    if (closed_) return;
    try {
      std::optional<mapping::FrameRecord> frame =
          decoder_->Decode(m, m.header.stamp_s - time_origin_s_, options_.topics.frames);
      if (!frame) {
        ++undecodable_;
        return;
      }
      mapping::InspectionFrame f;
      f.record = std::move(*frame);
      f.receive_time_s = UnixNow();
      if (first_receive_s_ == 0.0) first_receive_s_ = f.receive_time_s;
      last_receive_s_ = f.receive_time_s;
      // The stamp is the host's clock when it is within a second of it (a live camera), not in
      // a replayed bag.
      if (std::abs(m.header.stamp_s - f.receive_time_s) < 1.0) f.capture_time_s = m.header.stamp_s;
      inspection_->Push(std::move(f));
    } catch (...) {
      closed_ = true;
      failure_.Set(std::current_exception());
    }
  }

  // With navigation_mutex_ held.
  void AddNavigation(const OdometryMessage& m) {
    if (closed_) return;
    try {
      inspection_->AddNavigation({m.header.stamp_s - time_origin_s_,
                                  VehiclePoseInUwscanAxes(m.pose, options_.navigation.axes)});
      ++navigation_;
    } catch (...) {
      closed_ = true;
      failure_.Set(std::current_exception());
    }
  }

  const InspectionNodeOptions& options_;
  Failure& failure_;
  std::size_t capacity_;
  std::mutex frames_mutex_, navigation_mutex_;
  std::optional<FrameImageDecoder> decoder_;
  double time_origin_s_ = 0.0;
  mapping::LiveInspection* inspection_ = nullptr;
  std::deque<ImageMessage> pending_frames_;
  double first_receive_s_ = 0.0, last_receive_s_ = 0.0;  // Unix time, frames_mutex_
  std::deque<OdometryMessage> pending_navigation_;
  bool closed_ = false;
  std::atomic<std::int64_t> frames_{0}, undecodable_{0}, dropped_{0}, navigation_{0};
};

// Why the node stops now, "" to go on.
std::string StopReason(const InspectionNodeOptions& o, RosConnection& ros, const Intake& intake,
                       const std::function<bool()>& stop_requested, double idle_s) {
  if (stop_requested()) return "stop requested";
  if (!ros.Ok()) return "ROS shut the node down";
  if (o.max_frames > 0 && intake.frames() >= o.max_frames)
    return std::to_string(o.max_frames) + " frames received";
  if (o.idle_stop_s > 0.0 && intake.frames() > 0 && idle_s >= o.idle_stop_s) {
    return "no frame for " + std::to_string(o.idle_stop_s) + " s";
  }
  return "";
}

}  // namespace

void InspectionNodeOptions::Check() const {
  const OptionChecks check("InspectionNodeOptions");
  check.GreaterThan("description_wait_s", description_wait_s, 0.0, "s");
  check.AtLeast("mount_wait_s", mount_wait_s, 0.0, "s");
  check.GreaterThan("map_period_s", map_period_s, 0.0, "s");
  check.AtLeast("frame_queue", frame_queue, 1);
  check.AtLeast("max_frames", static_cast<double>(max_frames), 0);
  check.AtLeast("idle_stop_s", idle_stop_s, 0.0, "s");
  inspection.Check();
}

namespace {

// Everything a running node holds. The subscriptions end first (no callback runs after), then
// the parts go in the reverse of their order here: the inspection (its mapping thread calls the
// outlet), the outlet, the intake, the listener.
struct Node {
  explicit Node(RosConnection& r) : ros(r) {}
  ~Node() {
    StopCamera();
    ros.Unsubscribe();
    ros.SetErrorHandler({});
  }
  void StopCamera() {
    camera_stop = true;
    if (camera_thread.joinable()) camera_thread.join();
  }
  Node(const Node&) = delete;
  Node& operator=(const Node&) = delete;

  RosConnection& ros;
  Failure failure;
  std::unique_ptr<SetupListener> listener;
  std::unique_ptr<Intake> intake;  // holds no inspection after Close()
  std::unique_ptr<Outlet> outlet;
  std::unique_ptr<mapping::LiveInspection> inspection;
  // CameraInput: the camera, read on its own thread into the intake.
  std::unique_ptr<scanner::acquisition::FrameSource> camera;
  std::unique_ptr<mapping::CameraFrameDecoder> decoder;
  std::atomic<bool> camera_stop{false};
  mapping::ReadSummary camera_read;  // once the thread ended
  std::thread camera_thread;
};

// Frames and navigation are taken from the start (they wait in the intake), so that none is
// lost while the scanner's description and mount arrive.
void Subscribe(Node& node, const InspectionNodeOptions& o) {
  node.listener = std::make_unique<SetupListener>(node.ros, o, node.failure);
  node.intake = std::make_unique<Intake>(o, node.failure);
  Intake* intake = node.intake.get();
  if (o.navigation.source == NavigationSource::kOdometry) {
    node.ros.SubscribeOdometry(o.topics.odometry, o.frame_queue,
                               [intake](OdometryMessage&& m) { intake->OnOdometry(std::move(m)); });
  } else {
    node.ros.SubscribeTransforms(
        o.topics.tf, o.frame_queue, [intake, &o](std::vector<TransformMessage>&& ts) {
          if (std::optional<OdometryMessage> m = NavigationFromTransforms(ts, o.frames))
            intake->OnOdometry(std::move(*m));
        });
  }
  if (!o.camera) {
    node.ros.SubscribeImages(o.topics.frames, o.frame_queue,
                             [intake](ImageMessage&& m) { intake->OnImage(std::move(m)); });
  }
}

// CameraInput: the camera opened, its scanner and mount from its scene or scanner file.
DiveSetup OpenCamera(Node& node, const InspectionNodeOptions& o) {
  const CameraInput& c = *o.camera;
  node.camera = std::make_unique<scanner::acquisition::FrameSource>(c.settings);
  const mapping::AcquisitionContext context =
      mapping::MakeAcquisitionContext(c.scene, c.scanner_file, node.camera->payload(), o.producer);
  node.decoder =
      std::make_unique<mapping::CameraFrameDecoder>(node.camera->payload(), context, o.keep_images);
  DiveSetup setup;
  setup.header = context.header;
  setup.T_V_C = context.T_V_C;
  setup.mount = c.scene.empty()
                    ? "none for a real camera: the camera is taken at the vehicle's origin"
                    : "the scene the simulated camera serves";
  return setup;
}

void StartCamera(Node& node, const InspectionNodeOptions& o) {
  // The camera stops itself at max_frames: the node's watch would see the count a little late.
  const mapping::ReadLimits limits{o.max_frames, 0.0};
  node.camera_thread = std::thread([&node, limits] {
    mapping::ReadCallbacks callbacks;
    callbacks.consume = [&node](mapping::FrameRecord&& r,
                                const scanner::acquisition::AcquiredFrame& f) {
      node.intake->OnCameraFrame(std::move(r), f);
    };
    callbacks.stop_requested = [&node] { return node.camera_stop.load(); };
    try {
      node.camera_read = mapping::ReadFrames(*node.camera, *node.decoder, limits, callbacks);
    } catch (...) {
      node.failure.Set(std::current_exception());
    }
  });
}

void StartInspection(Node& node, const InspectionNodeOptions& o, const DiveSetup& setup) {
  mapping::DiveLogHeader header = setup.header;
  header.producer = o.producer;
  mapping::InspectionOptions options = o.inspection;
  options.fixed_scanner = false;
  node.outlet = std::make_unique<Outlet>(
      node.ros, o, setup.time_origin_s, setup.header.scan_pattern.frames_per_sweep(),
      [&node](std::exception_ptr e) { node.failure.Set(std::move(e)); });
  Outlet* outlet = node.outlet.get();
  node.inspection = std::make_unique<mapping::LiveInspection>(
      header, o.log, setup.T_V_C,
      header.navigation_noise.value_or(mapping::AssumedNavigationNoise()), options,
      [outlet](const mapping::MappedFrame& f) { outlet->OnMapped(f); });
  node.inspection->SetSubmapClosedCallback(
      [outlet](const mapping::Mapper& m) { outlet->OnSubmapClosed(m); });
  node.intake->Begin(setup, *node.inspection);
}

// Until a reason to stop; reports about once a second and keeps the node registered.
std::string Watch(Node& node, const InspectionNodeOptions& o,
                  const std::function<bool()>& stop_requested,
                  const std::function<void(const InspectionNodeStatus&)>& status) {
  const Clock::time_point start = Clock::now();
  Clock::time_point last_frame_change = start, last_status = start;
  std::int64_t last_frames = 0;
  while (!node.failure.IsSet()) {
    if (node.intake->frames() != last_frames) {
      last_frames = node.intake->frames();
      last_frame_change = Clock::now();
    }
    const std::string reason =
        StopReason(o, node.ros, *node.intake, stop_requested, SecondsSince(last_frame_change));
    if (!reason.empty()) return reason;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    if (SecondsSince(last_status) >= 1.0) {
      last_status = Clock::now();
      const bool master = node.ros.KeepRegistered();
      const double silent_s = last_frames > 0 ? SecondsSince(last_frame_change) : 0.0;
      if (status) {
        status({node.inspection->statistics(), master, SecondsSince(start), silent_s,
                node.intake->navigation()});
      }
    }
  }
  return "failed";
}

}  // namespace

InspectionNodeSummary RunInspectionNode(
    RosConnection& ros, const InspectionNodeOptions& o, const std::function<bool()>& stop_requested,
    const std::function<void(const InspectionNodeStatus&)>& status) {
  o.Check();
  Node node(ros);
  ros.SetErrorHandler([&node](std::exception_ptr e) { node.failure.Set(std::move(e)); });
  Subscribe(node, o);
  ros.Start(2);
  const DiveSetup setup =
      o.camera ? OpenCamera(node, o) : node.listener->Wait(node.failure, stop_requested);
  StartInspection(node, o, setup);
  if (o.camera) StartCamera(node, o);

  InspectionNodeSummary summary;
  summary.stop_reason = Watch(node, o, stop_requested, status);
  node.StopCamera();
  node.intake->Close();
  node.failure.Rethrow();
  if (node.intake->dropped() > 0) {
    throw Error(
        std::to_string(node.intake->dropped()) + " frames on " + o.topics.frames +
        " came before the scanner was known and beyond ~frame_queue; they are not in the log");
  }
  summary.result = node.inspection->Finish();
  node.outlet->Finish(summary.result);
  summary.frames_undecodable = node.intake->undecodable() + node.camera_read.undecodable;
  summary.camera_lost_frames = node.camera_read.source.lost_frames;
  summary.navigation_samples = node.intake->navigation();
  summary.receive_span_s = node.intake->receive_span_s();
  summary.sweeps_published = node.outlet->sweeps();
  std::tie(summary.sweep_latency_median_s, summary.sweep_latency_p95_s) =
      node.outlet->SweepLatency();
  summary.sweep_latency_by_minute = node.outlet->SweepLatencyByMinute();
  summary.maps_published = node.outlet->maps_published();
  summary.maps_replaced = node.outlet->maps_replaced();
  summary.reregistrations = ros.reregistrations();
  summary.described = setup.described;
  summary.mount = setup.mount;
  summary.time_origin_s = setup.time_origin_s;
  return summary;
}

}  // namespace uwscan::ros
