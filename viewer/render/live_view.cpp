#include "viewer/render/live_view.hpp"

#include <vtkCallbackCommand.h>
#include <vtkCommand.h>
#include <vtkPointGaussianMapper.h>
#include <vtkRenderWindowInteractor.h>
#include <vtkTextActor.h>

#include <chrono>
#include <cmath>
#include <deque>
#include <limits>
#include <map>
#include <mutex>
#include <thread>

#include "scanner/common/error.hpp"
#include "scanner/common/option_checks.hpp"
#include "viewer/render/display.hpp"
#include "viewer/render/view_interaction.hpp"
#include "viewer/render/vtk_scene.hpp"
#include "viewer/scene/point_colours.hpp"

namespace uwscan::viewer {
namespace {

// What the producers have handed over, shared under the view's mutex.
struct Shared {
  std::deque<std::shared_ptr<const LiveCloud>> clouds;
  std::map<std::string, TrajectoryLayer> tracks;
  std::map<int, LiveObject> objects;
  double newest_time_s = -std::numeric_limits<double>::infinity();
  std::uint64_t version = 0;  // bumped by every change
  bool stop = false;
  LiveViewStats stats;
};

// A copy the GUI thread draws from, taken under the lock in O(number of clouds).
struct Snapshot {
  std::vector<std::shared_ptr<const LiveCloud>> clouds;
  std::map<std::string, TrajectoryLayer> tracks;
  std::map<int, LiveObject> objects;
  std::uint64_t version = 0;
  bool stop = false;
  LiveViewStats stats;
};

template <typename T>
void RequireSize(const std::vector<T>& values, std::size_t points, const char* what) {
  if (!values.empty() && values.size() != points) {
    throw Error(std::string("live view: ") + what + " has " + std::to_string(values.size()) +
                " values for " + std::to_string(points) + " points");
  }
}

// The clouds of a snapshot as one layer (render anchor as origin), keeping a per-point array
// only when every cloud has it.
CloudLayer Combine(const std::vector<std::shared_ptr<const LiveCloud>>& clouds,
                   const Eigen::Vector3d& anchor_W) {
  CloudLayer layer;
  layer.name = "live";
  layer.origin = anchor_W;
  bool errors = true, intensities = true, ids = true, deviations = true;
  std::size_t n = 0;
  for (const auto& c : clouds) {
    n += c->points_W.size();
    errors = errors && c->error_m.size() == c->points_W.size();
    intensities = intensities && c->intensity.size() == c->points_W.size();
    ids = ids && c->object_ids.size() == c->points_W.size();
    deviations = deviations && c->deviation_m.size() == c->points_W.size();
  }
  layer.points.reserve(n);
  for (const auto& c : clouds) {
    for (const Eigen::Vector3d& p : c->points_W)
      layer.points.push_back((p - anchor_W).cast<float>());
    if (errors) layer.error_m.insert(layer.error_m.end(), c->error_m.begin(), c->error_m.end());
    if (intensities)
      layer.intensity.insert(layer.intensity.end(), c->intensity.begin(), c->intensity.end());
    if (ids)
      layer.object_ids.insert(layer.object_ids.end(), c->object_ids.begin(), c->object_ids.end());
    if (deviations)
      layer.deviation_m.insert(layer.deviation_m.end(), c->deviation_m.begin(),
                               c->deviation_m.end());
  }
  return layer;
}

}  // namespace

void LiveViewOptions::Check() const {
  render.Check();
  const OptionChecks check("LiveViewOptions");
  check.AtLeast("point_budget", point_budget, 1);
  check.NonNegative("decay_s", decay_s, "s");
  check.InRange("refresh_s", refresh_s, 0.0, 60.0, Interval::kOpenLow, "s");
}

struct LiveView::Impl {
  LiveViewOptions options;
  mutable std::mutex mutex;
  Shared shared;
  std::filesystem::path final_png;

  // Under the lock: drop the oldest clouds beyond the budget (never the newest) or the decay.
  void Enforce() {
    auto drop_front = [this] {
      shared.stats.points_held -= shared.clouds.front()->points_W.size();
      shared.clouds.pop_front();
      ++shared.stats.clouds_dropped;
    };
    while (shared.clouds.size() > 1 && shared.stats.points_held > options.point_budget)
      drop_front();
    if (options.decay_s > 0.0) {
      while (!shared.clouds.empty() &&
             shared.clouds.front()->time_s < shared.newest_time_s - options.decay_s) {
        drop_front();
      }
    }
  }

  Snapshot Take() const {
    const std::lock_guard<std::mutex> lock(mutex);
    return Snapshot{{shared.clouds.begin(), shared.clouds.end()},
                    shared.tracks,
                    shared.objects,
                    shared.version,
                    shared.stop,
                    shared.stats};
  }
};

LiveView::LiveView(const LiveViewOptions& options) : impl_(std::make_unique<Impl>()) {
  options.Check();
  impl_->options = options;
}

LiveView::~LiveView() = default;

void LiveView::Push(LiveCloud cloud) {
  const std::size_t n = cloud.points_W.size();
  RequireSize(cloud.error_m, n, "error_m");
  RequireSize(cloud.intensity, n, "intensity");
  RequireSize(cloud.object_ids, n, "object_ids");
  RequireSize(cloud.deviation_m, n, "deviation_m");
  if (n == 0) return;
  auto shared_cloud = std::make_shared<const LiveCloud>(std::move(cloud));
  const std::lock_guard<std::mutex> lock(impl_->mutex);
  Shared& s = impl_->shared;
  s.newest_time_s = std::max(s.newest_time_s, shared_cloud->time_s);
  s.stats.points_held += n;
  s.stats.points_received += static_cast<std::int64_t>(n);
  ++s.stats.clouds_received;
  s.clouds.push_back(std::move(shared_cloud));
  impl_->Enforce();
  ++s.version;
}

void LiveView::Push(LivePose pose) {
  const std::lock_guard<std::mutex> lock(impl_->mutex);
  Shared& s = impl_->shared;
  TrajectoryLayer& track = s.tracks[pose.track];
  track.name = pose.track;
  track.times_s.push_back(pose.time_s);
  track.positions_W.push_back(pose.T_W_B.translation());
  ++s.stats.poses_received;
  ++s.version;
}

void LiveView::Push(LiveObject object) {
  if (!object.mesh) throw Error("live view: object " + std::to_string(object.id) + " has no mesh");
  const std::lock_guard<std::mutex> lock(impl_->mutex);
  impl_->shared.objects[object.id] = std::move(object);
  ++impl_->shared.version;
}

void LiveView::RequestStop() {
  const std::lock_guard<std::mutex> lock(impl_->mutex);
  impl_->shared.stop = true;
}

void LiveView::SetFinalScreenshot(const std::filesystem::path& png) { impl_->final_png = png; }

LiveViewStats LiveView::stats() const {
  const std::lock_guard<std::mutex> lock(impl_->mutex);
  return impl_->shared.stats;
}

namespace {

// Everything the GUI thread owns: the VTK objects and what they were made from.
class LiveScene {
 public:
  LiveScene(const LiveViewOptions& options, vtkRenderWindow& window)
      : options_(options), render_(options.render), window_(window) {
    renderer_ = vtkSmartPointer<vtkRenderer>::New();
    const Rgb& bg = options.render.background;
    renderer_->SetBackground(bg.r / 255.0, bg.g / 255.0, bg.b / 255.0);
    if (options.render.eye_dome_lighting) internal::EnableEyeDomeLighting(*renderer_);
    status_ = internal::CornerText(bg);
    status_->SetDisplayPosition(10, options.render.height_px - 30);
    status_->SetInput("waiting for data");
    pick_ = internal::CornerText(bg);
    pick_->SetInput(options.offscreen ? "" : kLiveKeys);  // no key hints in a picture
    renderer_->AddViewProp(status_);
    renderer_->AddViewProp(pick_);
    window_.AddRenderer(renderer_);
  }

  static constexpr const char* kLiveKeys =
      "p: pick a point; f / t / s: fit / top / side; + / -: point size; e: EDL";

  vtkRenderer& renderer() { return *renderer_; }
  RenderOptions& render_options() { return render_; }
  const std::vector<internal::DrawnCloud>& clouds() const { return drawn_; }
  vtkTextActor& pick_text() { return *pick_; }

  // Rebuilds the actors when the snapshot holds news; true when it did.
  bool Update(const Snapshot& s) {
    if (s.version == drawn_version_) return false;
    drawn_version_ = s.version;
    if (!anchor_ && !s.clouds.empty()) anchor_ = s.clouds.front()->points_W.front();
    if (!anchor_) {
      for (const auto& [name, track] : s.tracks) {
        if (!track.positions_W.empty()) anchor_ = track.positions_W.front();
      }
    }
    if (!anchor_) return false;
    for (vtkProp* prop : props_) renderer_->RemoveViewProp(prop);
    props_.clear();
    drawn_.clear();
    AddClouds(s.clouds);
    int colour = 0;
    for (const auto& [name, track] : s.tracks) {
      props_.push_back(internal::TrajectoryActor(track, CategoricalColour(colour++), *anchor_));
    }
    for (const auto& [id, object] : s.objects) {
      props_.push_back(internal::MeshActor(MeshLayer{object.label, *object.mesh, object.T_W_O},
                                           CategoricalColour(id), *anchor_));
    }
    for (vtkProp* prop : props_) renderer_->AddViewProp(prop);
    status_->SetInput(Status(s.stats).c_str());
    if (!camera_placed_) {
      std::vector<vtkActor*> actors;
      for (const internal::DrawnCloud& cloud : drawn_) actors.push_back(cloud.actor);
      internal::ApplyCameraPreset(*renderer_, render_.camera, render_.up,
                                  internal::UnionBounds(actors));
      camera_placed_ = true;
    } else {
      renderer_->ResetCameraClippingRange();
    }
    return true;
  }

 private:
  void AddClouds(const std::vector<std::shared_ptr<const LiveCloud>>& clouds) {
    if (clouds.empty()) return;
    layer_ = Combine(clouds, *anchor_);
    const std::size_t stride = PointStride(layer_.size(), options_.point_budget);
    std::vector<float> scalars =
        PointScalars(layer_, render_.colour, render_.up.normalized(), stride);
    const ScalarRange range = SceneRange({scalars}, render_);
    const bool ids = layer_.object_ids.size() == layer_.size();
    std::vector<Rgb> colours;
    colours.reserve(layer_.size() / stride + 1);
    for (std::size_t i = 0, j = 0; i < layer_.size(); i += stride, ++j) {
      colours.push_back(
          PointColour(render_.colour, scalars.empty() ? 0.0f : scalars[j], range, 0,
                      ids ? std::optional<std::int32_t>(layer_.object_ids[i]) : std::nullopt));
    }
    internal::DrawnCloud drawn;
    drawn.actor = internal::PointActor(
        internal::PointPolyData(Eigen::Vector3d::Zero(), layer_.points, stride, colours),
        render_.point_size_px);
    drawn.layer = &layer_;
    drawn.stride = stride;
    drawn.scalars = std::move(scalars);
    props_.push_back(drawn.actor);
    drawn_.push_back(std::move(drawn));
    if (IsContinuous(render_.colour) && render_.colour_bar) {
      props_.push_back(
          internal::ColourBar(range,
                              std::string(ToString(render_.colour)) +
                                  (render_.colour == ColourMode::kIntensity ? "" : " m"),
                              render_.colour));
    }
  }

  static std::string Status(const LiveViewStats& s) {
    return std::to_string(s.points_held) + " points held, " + std::to_string(s.points_received) +
           " received in " + std::to_string(s.clouds_received) + " clouds (" +
           std::to_string(s.clouds_dropped) + " dropped), " + std::to_string(s.poses_received) +
           " poses";
  }

  const LiveViewOptions& options_;
  RenderOptions render_;
  vtkRenderWindow& window_;
  vtkSmartPointer<vtkRenderer> renderer_;
  vtkSmartPointer<vtkTextActor> status_, pick_;
  std::vector<vtkSmartPointer<vtkProp>> props_;
  std::vector<internal::DrawnCloud> drawn_;
  CloudLayer layer_;
  std::optional<Eigen::Vector3d> anchor_;
  std::uint64_t drawn_version_ = 0;
  bool camera_placed_ = false;
};

}  // namespace

void LiveView::Run(const std::string& title) {
  RequireDisplay();
  const LiveViewOptions& options = impl_->options;
  vtkSmartPointer<vtkRenderWindow> window =
      internal::MakeRenderWindow(options.render, options.offscreen);
  window->SetWindowName(title.c_str());
  LiveScene scene(options, *window);
  auto redraw = [this, &scene, &window] {
    const Snapshot s = impl_->Take();
    if (scene.Update(s)) {
      window->Render();
      const std::lock_guard<std::mutex> lock(impl_->mutex);
      ++impl_->shared.stats.redraws;
    }
    return s.stop;
  };
  const auto period = std::chrono::duration<double>(options.refresh_s);
  if (options.offscreen) {
    window->Render();
    while (!redraw()) std::this_thread::sleep_for(period);
  } else {
    vtkNew<vtkRenderWindowInteractor> interactor;
    interactor->SetRenderWindow(window);
    internal::InstallViewControls(
        *interactor, scene.renderer(),
        [&scene]() -> const std::vector<internal::DrawnCloud>& { return scene.clouds(); },
        options.render.colour, scene.render_options(), scene.pick_text());
    interactor->Initialize();
    // The timer is where the queue is drained: on this thread, between VTK's own events.
    vtkNew<vtkCallbackCommand> on_timer;
    struct TimerContext {
      std::function<bool()> redraw;
      vtkRenderWindowInteractor* interactor;
    } context{redraw, interactor};
    on_timer->SetClientData(&context);
    on_timer->SetCallback([](vtkObject*, unsigned long, void* data, void*) {
      auto* c = static_cast<TimerContext*>(data);
      if (c->redraw()) c->interactor->TerminateApp();
    });
    interactor->AddObserver(vtkCommand::TimerEvent, on_timer);
    interactor->CreateRepeatingTimer(
        static_cast<unsigned long>(std::lround(options.refresh_s * 1000.0)));
    window->Render();
    interactor->Start();
  }
  if (!impl_->final_png.empty() && impl_->Take().stop) {
    redraw();
    window->Render();
    internal::WriteWindowPng(*window, impl_->final_png);
  }
}

}  // namespace uwscan::viewer
