#include "ros/node/map_publisher.hpp"

#include <optional>
#include <utility>
#include <vector>

namespace uwscan::ros {

MapPublisher::MapPublisher(RosConnection& ros, int map_id, NavigationAxes axes,
                           std::shared_ptr<const mapping::LiveDeviation> reference,
                           std::function<void(std::exception_ptr)> on_failure)
    : ros_(ros),
      map_id_(map_id),
      axes_(axes),
      reference_(std::move(reference)),
      on_failure_(std::move(on_failure)),
      thread_([this] { Run(); }) {}

MapPublisher::~MapPublisher() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stopping_ = true;
  }
  changed_.notify_all();
  thread_.join();
}

void MapPublisher::Submit(perception::PointCloud map_W, Header header) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (failure_ || stopping_) return;
    if (pending_) {
      ++replaced_;
      spare_ = std::move(pending_->map_W);
    }
    pending_ = Pending{std::move(map_W), std::move(header)};
  }
  changed_.notify_all();
}

void MapPublisher::PublishLast(perception::PointCloud map_W, Header header) {
  std::unique_lock<std::mutex> lock(mutex_);
  if (pending_) ++replaced_;
  pending_.reset();
  changed_.wait(lock, [this] { return !busy_ || failure_; });
  if (failure_) std::rethrow_exception(failure_);
  busy_ = true;  // the thread takes nothing while this one publishes
  lock.unlock();
  std::exception_ptr failure;
  try {
    Publish({std::move(map_W), std::move(header)});
  } catch (...) {
    failure = std::current_exception();
  }
  lock.lock();
  busy_ = false;
  if (failure) std::rethrow_exception(failure);
}

perception::PointCloud MapPublisher::TakeSpare() {
  std::lock_guard<std::mutex> lock(mutex_);
  return std::exchange(spare_, {});
}

std::int64_t MapPublisher::published() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return published_;
}

std::int64_t MapPublisher::replaced() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return replaced_;
}

void MapPublisher::Run() {
  std::unique_lock<std::mutex> lock(mutex_);
  while (true) {
    changed_.wait(lock, [this] { return stopping_ || (pending_ && !busy_); });
    if (stopping_) return;
    std::optional<Pending> next = std::move(pending_);
    pending_.reset();
    busy_ = true;
    lock.unlock();
    std::exception_ptr failure;
    try {
      Publish(*next);
    } catch (...) {
      failure = std::current_exception();
    }
    lock.lock();
    spare_ = std::move(next->map_W);
    next.reset();
    busy_ = false;
    if (failure) {
      failure_ = failure;
      on_failure_(failure);
    }
    changed_.notify_all();
    if (failure) return;
  }
}

// The map in the navigation's axes; with a reference, each point's deviation from it (taken in
// uwscan's world frame, where the reference is) as the field "deviation".
void MapPublisher::Publish(const Pending& p) {
  CloudMessage c;
  c.header = p.header;
  c.points.reserve(p.map_W.size());
  for (std::size_t i = 0; i < p.map_W.size(); ++i) {
    c.points.push_back(WorldPointInNavigationAxes(p.map_W.Point(i), axes_).cast<float>());
  }
  if (reference_) {
    std::vector<Eigen::Vector3d> points_W(p.map_W.size());
    for (std::size_t i = 0; i < p.map_W.size(); ++i) points_W[i] = p.map_W.Point(i);
    c.scalar_name = "deviation";
    c.scalars = reference_->Deviations(points_W);
  }
  ros_.Publish(map_id_, c);
  std::lock_guard<std::mutex> lock(mutex_);
  ++published_;
}

}  // namespace uwscan::ros
