#include "scanner/acquisition/frame_source.hpp"

#include <arpa/inet.h>
#include <arv.h>

#include <atomic>
#include <condition_variable>
#include <cstdio>
#include <cstring>
#include <deque>
#include <mutex>
#include <thread>

#include "scanner/common/error.hpp"
#include "scanner/common/option_checks.hpp"

namespace uwscan::scanner::acquisition {
namespace {

using Clock = std::chrono::steady_clock;

// Throws uwscan::Error with `what` and Aravis's message when `error` is set (and frees it).
void ThrowIf(GError* error, const std::string& what) {
  if (error == nullptr) return;
  const std::string message = error->message != nullptr ? error->message : "unknown error";
  g_error_free(error);
  throw Error(what + ": " + message);
}

ArvPixelFormat ToArv(PixelFormat format) {
  return format == PixelFormat::kMono8 ? ARV_PIXEL_FORMAT_MONO_8 : ARV_PIXEL_FORMAT_MONO_16;
}

}  // namespace

const char* ToString(TriggerMode mode) {
  switch (mode) {
    case TriggerMode::kFreeRun:
      return "free";
    case TriggerMode::kSoftware:
      return "software";
    case TriggerMode::kLine:
      return "line";
  }
  return "?";
}

std::optional<TriggerMode> TriggerModeFromString(const std::string& name) {
  if (name == "free") return TriggerMode::kFreeRun;
  if (name == "software") return TriggerMode::kSoftware;
  if (name == "line") return TriggerMode::kLine;
  return std::nullopt;
}

const char* ToString(ReceivePath path) {
  return path == ReceivePath::kPacketSocket ? "packet" : "udp";
}

std::optional<ReceivePath> ReceivePathFromString(const std::string& name) {
  if (name == "packet") return ReceivePath::kPacketSocket;
  if (name == "udp") return ReceivePath::kUdpSocket;
  return std::nullopt;
}

void CameraSettings::Check() const {
  const OptionChecks check("CameraSettings");
  in_addr parsed{};
  // Aravis takes anything else for a device name and looks for it on every interface.
  if (inet_pton(AF_INET, address.c_str(), &parsed) != 1) {
    check.Fail("address",
               "an IPv4 address a.b.c.d (cameras are opened by address, never searched for by "
               "name)",
               OptionQuotedText(address));
  }
  check.AtLeast("roi_x_px", roi_x_px, 0);
  check.AtLeast("roi_y_px", roi_y_px, 0);
  check.AtLeast("roi_width_px", roi_width_px, 0);
  check.AtLeast("roi_height_px", roi_height_px, 0);
  check.Require((roi_width_px > 0) == (roi_height_px > 0), "roi_height_px",
                "> 0 with roi_width_px > 0, 0 with roi_width_px 0 (roi_width_px is " +
                    std::to_string(roi_width_px) + ")",
                roi_height_px);
  check.NonNegative("exposure_us", exposure_us, "us");
  check.Finite("gain", gain);
  check.InRange("frame_rate_hz", frame_rate_hz, 0.0, 100000.0, Interval::kClosed, "Hz");
  check.Require(packet_size_bytes == 0 || (packet_size_bytes >= 576 && packet_size_bytes <= 65000),
                "packet_size_bytes", "0 or in [576, 65000] bytes", packet_size_bytes);
  check.InRange("buffers", buffers, 2, 100000);
  check.InRange("watchdog_s", watchdog_s, 0.0, 3600.0, Interval::kOpenLow, "s");
  check.InRange("frame_retention_s", frame_retention_s, 0.0, 60.0, Interval::kOpenLow, "s");
  check.InRange("control_wait_s", control_wait_s, 0.0, 3600.0, Interval::kClosed, "s");
  check.Require(trigger != TriggerMode::kLine || !trigger_line.empty(), "trigger_line",
                "a line name such as Line0 (trigger is line)", "''");
}

struct FrameSource::Impl {
  CameraSettings settings;
  PayloadDescription payload;
  ArvCamera* camera = nullptr;
  std::atomic<ArvStream*> stream{nullptr};
  std::size_t payload_bytes = 0;
  bool started = false;

  // The bounded queue the stream callback fills (never more than `buffers` entries).
  std::mutex mutex;
  std::condition_variable ready;
  std::deque<ArvBuffer*> done;

  FrameIdUnwrapper unwrapper;
  FrameSourceStatistics stats;
  std::int64_t sequence = 0;
  int session = 0;
  Clock::time_point start_time;
  Clock::time_point last_frame_time;
  bool in_gap = false;
  Clock::time_point next_reopen_attempt;

  static void OnStream(void* user_data, ArvStreamCallbackType type, ArvBuffer* buffer) {
    if (type != ARV_STREAM_CALLBACK_TYPE_BUFFER_DONE || buffer == nullptr) return;
    auto* self = static_cast<Impl*>(user_data);
    ArvStream* s = self->stream.load();
    if (s == nullptr) return;
    // Aravis has just put `buffer` on its output queue: move it to ours.
    ArvBuffer* popped = arv_stream_try_pop_buffer(s);
    if (popped == nullptr) return;
    {
      std::lock_guard<std::mutex> lock(self->mutex);
      self->done.push_back(popped);
    }
    self->ready.notify_one();
  }

  // Opens the camera, waiting up to `control_wait_s` for control of it (0: one attempt).
  void Open(double control_wait_s) {
    GError* error = nullptr;
    camera = arv_camera_new(settings.address.c_str(), &error);
    if (camera == nullptr || error != nullptr) {
      const std::string message =
          error != nullptr && error->message != nullptr ? error->message : "no answer";
      if (error != nullptr) g_error_free(error);
      if (camera != nullptr) g_clear_object(&camera);
      throw Error("camera " + settings.address + ": no GigE Vision camera answers there (" +
                  message + ")");
    }
    try {
      TakeControl(control_wait_s);
      Configure();
    } catch (...) {
      g_clear_object(&camera);
      throw;
    }
  }

  // Aravis asks for control when it opens a GigE camera and carries on as a monitor when
  // refused. A controller that died keeps the camera until its heartbeat runs out: ask again
  // until then, so that a restarted acquire takes over from a killed one.
  void TakeControl(double wait_s) {
    const std::string where = "camera " + settings.address;
    if (!arv_camera_is_gv_device(camera)) throw Error(where + ": not a GigE Vision camera");
    ArvGvDevice* device = ARV_GV_DEVICE(arv_camera_get_device(camera));
    const Clock::time_point start = Clock::now();
    while (!arv_gv_device_is_controller(device)) {
      const double waited_s = std::chrono::duration<double>(Clock::now() - start).count();
      if (waited_s >= wait_s) {
        char seconds[32];
        std::snprintf(seconds, sizeof seconds, "%.1f", waited_s);
        throw Error(where + ": another program controls the camera (control refused, waited " +
                    seconds + " s; is another acquire running?)");
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(250));
      GError* error = nullptr;
      arv_gv_device_take_control(device, &error);
      if (error != nullptr) g_error_free(error);
    }
  }

  void Configure() {
    GError* error = nullptr;
    const std::string where = "camera " + settings.address;
    const char* vendor = arv_camera_get_vendor_name(camera, nullptr);
    const char* model = arv_camera_get_model_name(camera, nullptr);
    payload.vendor = vendor != nullptr ? vendor : "";
    payload.model = model != nullptr ? model : "";

    arv_camera_set_acquisition_mode(camera, ARV_ACQUISITION_MODE_CONTINUOUS, &error);
    ThrowIf(error, where + ": AcquisitionMode Continuous refused");
    if (settings.pixel_format) {
      arv_camera_set_pixel_format(camera, ToArv(*settings.pixel_format), &error);
      ThrowIf(error, where + ": PixelFormat refused");
    }
    if (settings.roi_width_px > 0) {
      arv_camera_set_region(camera, settings.roi_x_px, settings.roi_y_px, settings.roi_width_px,
                            settings.roi_height_px, &error);
      ThrowIf(error, where + ": region of interest refused");
    }
    if (settings.exposure_us > 0.0) {
      arv_camera_set_exposure_time(camera, settings.exposure_us, &error);
      ThrowIf(error, where + ": ExposureTime refused");
    }
    if (settings.gain >= 0.0) {
      arv_camera_set_gain(camera, settings.gain, &error);
      ThrowIf(error, where + ": Gain refused");
    }
    // The frame rate first: Aravis clears the triggers when it sets one.
    if (settings.frame_rate_hz > 0.0) {
      arv_camera_set_frame_rate(camera, settings.frame_rate_hz, &error);
      ThrowIf(error, where + ": AcquisitionFrameRate refused");
    }
    switch (settings.trigger) {
      case TriggerMode::kFreeRun:
        arv_camera_clear_triggers(camera, &error);
        break;
      case TriggerMode::kSoftware:
        arv_camera_set_trigger(camera, "Software", &error);
        break;
      case TriggerMode::kLine:
        arv_camera_set_trigger(camera, settings.trigger_line.c_str(), &error);
        break;
    }
    ThrowIf(error, where + ": trigger " + ToString(settings.trigger) + " refused");
    if (settings.packet_size_bytes > 0) {
      arv_camera_gv_set_packet_size(camera, settings.packet_size_bytes, &error);
      ThrowIf(error, where + ": GevSCPSPacketSize refused");
    }
    if (settings.receive_path == ReceivePath::kUdpSocket) {
      arv_gv_device_set_stream_options(ARV_GV_DEVICE(arv_camera_get_device(camera)),
                                       ARV_GV_STREAM_OPTION_PACKET_SOCKET_DISABLED);
    }
    DescribePayload();
  }

  void DescribePayload() {
    GError* error = nullptr;
    const std::string where = "camera " + settings.address;
    gint x = 0, y = 0, width = 0, height = 0;
    arv_camera_get_region(camera, &x, &y, &width, &height, &error);
    ThrowIf(error, where + ": cannot read Width and Height");
    const ArvPixelFormat format = arv_camera_get_pixel_format(camera, &error);
    ThrowIf(error, where + ": cannot read PixelFormat");
    if (format != ARV_PIXEL_FORMAT_MONO_8 && format != ARV_PIXEL_FORMAT_MONO_16) {
      throw Error(where + ": pixel format " + std::to_string(format) +
                  " is neither Mono8 nor Mono16");
    }
    payload_bytes = arv_camera_get_payload(camera, &error);
    ThrowIf(error, where + ": cannot read PayloadSize");
    payload.payload_width_px = width;
    payload.payload_height_px = height;
    payload.format = format == ARV_PIXEL_FORMAT_MONO_8 ? PixelFormat::kMono8 : PixelFormat::kMono16;
    payload.uwscan_layout = arv_camera_is_feature_available(camera, "UwscanPayloadMode", nullptr);
    payload.metadata_row = payload.uwscan_layout;
    if (!payload.uwscan_layout) {
      payload.profile = false;
      payload.image_layout = {width, height, payload.format};
      return;
    }
    const char* mode = arv_camera_get_string(camera, "UwscanPayloadMode", &error);
    ThrowIf(error, where + ": cannot read UwscanPayloadMode");
    const char* axis = arv_camera_get_string(camera, "UwscanStripeAxis", &error);
    ThrowIf(error, where + ": cannot read UwscanStripeAxis");
    payload.profile = mode != nullptr && std::strcmp(mode, "Profile") == 0;
    if (payload.profile) {
      if (payload.format != PixelFormat::kMono16)
        throw Error(where + ": profile payloads must be Mono16");
      ProfileLayout& p = payload.profile_layout;
      p.axis = axis != nullptr && std::strcmp(axis, "Columns") == 0 ? StripeAxis::kColumns
                                                                    : StripeAxis::kRows;
      p.lines = width;
      p.peak_rows = height - 1;
      const gint64 image_width = arv_camera_get_integer(camera, "UwscanImageWidth", &error);
      ThrowIf(error, where + ": cannot read UwscanImageWidth");
      const gint64 image_height = arv_camera_get_integer(camera, "UwscanImageHeight", &error);
      ThrowIf(error, where + ": cannot read UwscanImageHeight");
      p.line_length_px = static_cast<int>(p.axis == StripeAxis::kRows ? image_width : image_height);
      p.Check();
    } else {
      if (height < 2)
        throw Error(where + ": an image payload needs a metadata row below the image");
      payload.image_layout = {width, height - 1, payload.format};
      payload.image_layout.Check();
    }
  }

  void CreateStream() {
    GError* error = nullptr;
    ArvStream* s = arv_camera_create_stream(camera, &Impl::OnStream, this, &error);
    if (s == nullptr || error != nullptr) {
      if (s != nullptr) g_object_unref(s);
      ThrowIf(error, "camera " + settings.address + ": cannot open a stream");
      throw Error("camera " + settings.address + ": cannot open a stream");
    }
    if (ARV_IS_GV_STREAM(s)) {
      g_object_set(s, "frame-retention", static_cast<guint>(settings.frame_retention_s * 1e6),
                   nullptr);
    }
    for (int i = 0; i < settings.buffers; ++i)
      arv_stream_push_buffer(s, arv_buffer_new_allocate(payload_bytes));
    stream.store(s);
  }

  void StartAcquisition() {
    GError* error = nullptr;
    // A controller that died may have left the camera acquiring, still sending to its own
    // (now closed) port: stop first, so that the start sends to this stream.
    arv_camera_stop_acquisition(camera, &error);
    if (error != nullptr) g_clear_error(&error);
    arv_camera_start_acquisition(camera, &error);
    ThrowIf(error, "camera " + settings.address + ": AcquisitionStart refused");
  }

  // Stops, drops the stream (joining its thread) and the camera; Aravis errors are ignored
  // here, since the camera may be gone.
  void Close() {
    if (camera != nullptr && started) arv_camera_stop_acquisition(camera, nullptr);
    ArvStream* s = stream.exchange(nullptr);
    if (s != nullptr) {
      stats.aravis_missing_frames += arv_stream_get_info_uint64_by_name(s, "n_missing_frames");
      guint64 completed = 0, failures = 0, underruns = 0;
      arv_stream_get_statistics(s, &completed, &failures, &underruns);
      stats.aravis_underruns += underruns;
      g_object_unref(s);
    }
    {
      std::lock_guard<std::mutex> lock(mutex);
      for (ArvBuffer* b : done) g_object_unref(b);
      done.clear();
    }
    if (camera != nullptr) g_clear_object(&camera);
  }

  double Since(Clock::time_point t) const {
    return std::chrono::duration<double>(t - start_time).count();
  }

  // The watchdog: a camera silent for watchdog_s is reopened with the same settings.
  void Watchdog() {
    const Clock::time_point now = Clock::now();
    if (!started) return;
    if (!in_gap) {
      if (std::chrono::duration<double>(now - last_frame_time).count() < settings.watchdog_s)
        return;
      in_gap = true;
      CameraGap gap;
      gap.silent_after_s = Since(last_frame_time);
      stats.gaps.push_back(gap);
      Close();
      next_reopen_attempt = now;
    }
    if (camera != nullptr || now < next_reopen_attempt) return;
    ++stats.gaps.back().reopen_attempts;
    try {
      Open(0.0);  // one attempt: the watchdog tries again shortly
      CreateStream();
      StartAcquisition();
      ++session;
      unwrapper.Reset();
    } catch (const Error&) {
      Close();
      next_reopen_attempt = Clock::now() + std::chrono::milliseconds(200);
    }
  }
};

FrameSource::FrameSource(const CameraSettings& settings) : impl_(std::make_unique<Impl>()) {
  settings.Check();
  impl_->settings = settings;
  impl_->Open(settings.control_wait_s);
}

FrameSource::~FrameSource() { impl_->Close(); }

const PayloadDescription& FrameSource::payload() const { return impl_->payload; }
const CameraSettings& FrameSource::settings() const { return impl_->settings; }

void FrameSource::Start() {
  if (impl_->started) return;
  impl_->CreateStream();
  impl_->StartAcquisition();
  impl_->started = true;
  impl_->start_time = Clock::now();
  impl_->last_frame_time = impl_->start_time;
}

std::optional<AcquiredFrame> FrameSource::Next(std::chrono::milliseconds timeout) {
  Impl& m = *impl_;
  if (!m.started) throw Error("frame source: Next() before Start()");
  const Clock::time_point deadline = Clock::now() + timeout;
  while (true) {
    ArvBuffer* buffer = nullptr;
    {
      std::unique_lock<std::mutex> lock(m.mutex);
      const Clock::time_point wake =
          std::min(deadline, Clock::now() + std::chrono::milliseconds(100));
      m.ready.wait_until(lock, wake, [&m] { return !m.done.empty(); });
      if (!m.done.empty()) {
        buffer = m.done.front();
        m.done.pop_front();
      }
    }
    if (buffer == nullptr) {
      m.Watchdog();
      if (Clock::now() >= deadline) return std::nullopt;
      continue;
    }
    ArvStream* s = m.stream.load();
    const ArvBufferStatus status = arv_buffer_get_status(buffer);
    const std::uint16_t id = static_cast<std::uint16_t>(arv_buffer_get_frame_id(buffer));
    const FrameIdUnwrapper::Step step = m.unwrapper.Next(id);
    m.last_frame_time = Clock::now();
    if (m.in_gap) {
      m.in_gap = false;
      m.stats.gaps.back().resumed_at_s = m.Since(m.last_frame_time);
    }
    if (step.stale) {
      ++m.stats.stale_frames;
      arv_stream_push_buffer(s, buffer);
      continue;
    }
    m.stats.lost_frames += step.lost_before;
    if (status != ARV_BUFFER_STATUS_SUCCESS) {
      ++m.stats.lost_frames;
      ++m.stats.incomplete_frames;
      arv_stream_push_buffer(s, buffer);
      continue;
    }
    AcquiredFrame frame;
    frame.sequence = m.sequence++;
    frame.frame_id = id;
    frame.frame_number = step.frame_number;
    frame.lost_before = step.lost_before;
    frame.session = m.session;
    frame.camera_timestamp_ns = arv_buffer_get_timestamp(buffer);
    frame.host_timestamp_ns = arv_buffer_get_system_timestamp(buffer);
    size_t size = 0;
    const auto* data = static_cast<const std::uint8_t*>(arv_buffer_get_data(buffer, &size));
    frame.payload.assign(data, data + size);
    arv_stream_push_buffer(s, buffer);
    ++m.stats.frames;
    m.stats.bytes += static_cast<std::int64_t>(size);
    return frame;
  }
}

void FrameSource::SoftwareTrigger() {
  if (impl_->camera == nullptr) return;  // reopening: the trigger is lost with the camera
  GError* error = nullptr;
  arv_camera_software_trigger(impl_->camera, &error);
  ThrowIf(error, "camera " + impl_->settings.address + ": TriggerSoftware refused");
}

void FrameSource::Stop() {
  if (!impl_->started) return;
  impl_->Close();
  impl_->started = false;
}

FrameSourceStatistics FrameSource::statistics() const {
  FrameSourceStatistics s = impl_->stats;
  if (ArvStream* stream = impl_->stream.load()) {
    s.aravis_missing_frames += arv_stream_get_info_uint64_by_name(stream, "n_missing_frames");
    guint64 completed = 0, failures = 0, underruns = 0;
    arv_stream_get_statistics(stream, &completed, &failures, &underruns);
    s.aravis_underruns += underruns;
  }
  return s;
}

double FrameSource::ElapsedSeconds() const { return impl_->Since(Clock::now()); }

}  // namespace uwscan::scanner::acquisition
