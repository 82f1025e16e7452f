#include "scanner/acquisition/fake_camera.hpp"

#include <arv.h>
#include <omp.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <filesystem>
#include <fstream>
#include <random>
#include <vector>

#include "scanner/acquisition/fake_camera_wakeup.hpp"
#include "scanner/common/error.hpp"
#include "scanner/common/option_checks.hpp"

namespace uwscan::scanner {
extern const char* const kFakeCameraGenicamXml;
}

namespace uwscan::scanner::acquisition {
namespace {

// uwscan's registers in the fake camera's memory (data/genicam/uwscan_fake_camera.xml).
constexpr guint32 kRegPayloadMode = 0x8000;
constexpr guint32 kRegStripeAxis = 0x8004;
constexpr guint32 kRegPeakRows = 0x8008;
constexpr guint32 kRegImageWidth = 0x800c;
constexpr guint32 kRegImageHeight = 0x8010;
// GigE Vision bootstrap strings.
constexpr guint32 kManufacturerName = 0x48;
constexpr guint32 kModelName = 0x68;

// Deterministic per-frame draw in [0, 1) from (seed, counter).
double Uniform(std::uint64_t seed, std::uint64_t counter) {
  std::uint64_t z = seed * 0x9E3779B97F4A7C15ull + counter + 0x632BE59BD9B4E019ull;
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  z ^= z >> 31;
  return static_cast<double>(z >> 11) * 0x1.0p-53;
}

void WriteString(ArvFakeCamera* camera, guint32 address, const std::string& text,
                 std::size_t length) {
  std::vector<char> bytes(length, 0);
  std::memcpy(bytes.data(), text.data(), std::min(text.size(), length - 1));
  arv_fake_camera_write_memory(camera, address, static_cast<guint32>(length), bytes.data());
}

}  // namespace

const char* ToString(FakeCameraMode mode) {
  return mode == FakeCameraMode::kImage ? "image" : "profile";
}

void FakeCameraOptions::Check() const {
  const OptionChecks check("FakeCameraOptions");
  check.Require(!address.empty(), "address", "an address to answer on", "''");
  check.Require(!serial.empty() && serial.size() <= 15, "serial", "1 to 15 characters",
                OptionQuotedText(serial));
  check.InRange(
      "frame_rate_hz", frame_rate_hz, 0.0, 1000.0, Interval::kClosed,
      "frames/s (0 = the scan pattern's rate; Aravis's fake camera runs at 1000 at most)");
  check.InRange("loss_ratio", loss_ratio, 0.0, 1.0, Interval::kOpenHigh);
  check.InRange("peak_rows", peak_rows, 1, 64);
  check.AtLeast("threads", threads, 0);
}

struct FakeCamera::Impl {
  FakeCameraOptions options;
  SimulatedMirrorDriver driver;
  std::int64_t frame_count = 0;
  std::int64_t frames_per_dive_sweeps = 1;  // sweeps in one pass over the simulated frames
  double frame_rate = 0.0;
  double frame_period_s = 0.0;
  // Profile mode: the peak rows of each simulated frame (metadata row added when sent).
  ProfileLayout profile_layout;
  std::vector<std::vector<std::uint8_t>> peak_rows;
  std::vector<int> peaks_dropped;
  // Image mode: the rendered frames.
  std::vector<StripeFrame> images;
  int image_width = 0;
  int image_height = 0;
  std::vector<double> frame_times_s;
  std::vector<int> frame_sweeps;

  ArvGvFakeCamera* gv = nullptr;
  std::unique_ptr<FakeCameraWakeup> wakeup;  // stopped before gv goes (see ~Impl)
  std::atomic<std::uint64_t> sent{0};
  std::atomic<std::uint64_t> dropped{0};
  std::atomic<std::uint64_t> peaks_lost{0};
  std::uint64_t counter = 0;  // fake camera thread only

  explicit Impl(const sim::Simulator& simulator) : driver(simulator.scan_pattern()) {}
  // Stops the wake-up, then the fake camera's thread (joined), before the frames it reads go
  // away; also when Start() fails half-way.
  ~Impl() {
    wakeup.reset();
    if (gv != nullptr) g_clear_object(&gv);
  }
  Impl(const Impl&) = delete;
  Impl& operator=(const Impl&) = delete;

  static void Fill(ArvBuffer* buffer, void* data, guint32 exposure_us, guint32 /*gain*/,
                   ArvPixelFormat pixel_format) {
    static_cast<Impl*>(data)->FillFrame(buffer, exposure_us, pixel_format);
  }

  void FillFrame(ArvBuffer* buffer, guint32 exposure_us, ArvPixelFormat pixel_format) {
    const std::uint64_t n = counter++;
    const std::int64_t index =
        static_cast<std::int64_t>(n % static_cast<std::uint64_t>(frame_count));
    const std::uint64_t pass = n / static_cast<std::uint64_t>(frame_count);
    const MirrorCommand command = driver.OnTrigger(n);
    FrameMetadata metadata;
    metadata.frame_counter = n;
    metadata.mirror_command = command.command;
    metadata.sweep = frame_sweeps[static_cast<std::size_t>(index)] +
                     static_cast<int>(pass * static_cast<std::uint64_t>(frames_per_dive_sweeps));
    metadata.exposure_us = exposure_us;
    const double time_s =
        frame_times_s[static_cast<std::size_t>(index)] +
        static_cast<double>(pass) * static_cast<double>(frame_count) * frame_period_s;
    metadata.timestamp_ns = static_cast<std::uint64_t>(std::llround(std::max(0.0, time_s) * 1e9));

    // The fill callback gets no payload size from Aravis (arv_buffer_get_data reports 0 here):
    // it follows from the region and the pixel format.
    const int width = static_cast<int>(arv_buffer_get_image_width(buffer));
    const int height = static_cast<int>(arv_buffer_get_image_height(buffer));
    const int bytes_per_pixel = pixel_format == ARV_PIXEL_FORMAT_MONO_16 ? 2 : 1;
    const std::size_t row_bytes = static_cast<std::size_t>(width) * bytes_per_pixel;
    const std::size_t size = row_bytes * static_cast<std::size_t>(height);
    auto* out = static_cast<std::uint8_t*>(const_cast<void*>(arv_buffer_get_data(buffer, nullptr)));
    if (out == nullptr || size == 0) return;
    std::memset(out, 0, size);
    const std::span<std::uint8_t> payload(out, size);
    if (!images.empty()) {
      FillImage(payload, index, width, height, bytes_per_pixel, buffer);
    } else if (width == profile_layout.lines && height == profile_layout.peak_rows + 1 &&
               bytes_per_pixel == 2) {
      const std::vector<std::uint8_t>& rows = peak_rows[static_cast<std::size_t>(index)];
      std::memcpy(out, rows.data(), rows.size());
      peaks_lost += static_cast<std::uint64_t>(peaks_dropped[static_cast<std::size_t>(index)]);
    }
    // (A region or format that profile mode cannot carry is sent without peaks.)
    if (row_bytes >= kMetadataBytes && height >= 1) {
      EncodeMetadata(metadata, payload.subspan(row_bytes * static_cast<std::size_t>(height - 1)));
    }
    ++sent;
    // Loss: every packet of this frame is withheld (the fake camera sends right after filling).
    const bool lose = options.loss_ratio > 0.0 && Uniform(options.seed, n) < options.loss_ratio;
    if (lose) ++dropped;
    g_object_set(gv, "gvsp-lost-ratio", lose ? 1.0 : 0.0, nullptr);
  }

  void FillImage(std::span<std::uint8_t> payload, std::int64_t index, int width, int height,
                 int bytes_per_pixel, ArvBuffer* buffer) const {
    const StripeFrame& frame = images[static_cast<std::size_t>(index)];
    const int x0 = static_cast<int>(arv_buffer_get_image_x(buffer));
    const int y0 = static_cast<int>(arv_buffer_get_image_y(buffer));
    const bool source16 = frame.format == PixelFormat::kMono16;
    for (int r = 0; r < height - 1; ++r) {
      const int v = y0 + r;
      if (v >= frame.height_px) break;
      std::uint8_t* row = payload.data() + static_cast<std::size_t>(r) * width * bytes_per_pixel;
      for (int c = 0; c < width; ++c) {
        const int u = x0 + c;
        if (u >= frame.width_px) break;
        const std::size_t i = static_cast<std::size_t>(v) * frame.width_px + u;
        const int value16 = source16 ? frame.mono16[i] : frame.mono8[i] * 257;
        if (bytes_per_pixel == 2) {
          const auto w = static_cast<std::uint16_t>(value16);
          std::memcpy(row + 2 * c, &w, 2);
        } else {
          row[c] = source16 ? static_cast<std::uint8_t>(value16 >> 8) : frame.mono8[i];
        }
      }
    }
  }

  void Prepare(const sim::Simulator& simulator, const std::function<void(double)>& progress) {
    frame_count = simulator.frame_count();
    if (frame_count <= 0) throw Error("fake camera: the scene has no frames");
    frame_period_s = simulator.frame_period_s();
    const int per_sweep = simulator.scan_pattern().frames_per_sweep();
    frames_per_dive_sweeps = (frame_count + per_sweep - 1) / per_sweep;
    const PinholeCamera& intrinsics = simulator.scanner().camera().camera;
    image_width = intrinsics.width_px;
    image_height = intrinsics.height_px;
    const sim::Scene& scene = simulator.scene();
    profile_layout.axis = scene.detector.axis;
    profile_layout.lines = profile_layout.axis == StripeAxis::kRows ? image_height : image_width;
    profile_layout.line_length_px =
        profile_layout.axis == StripeAxis::kRows ? image_width : image_height;
    profile_layout.peak_rows = options.peak_rows;
    profile_layout.Check();
    const bool image_mode = options.mode == FakeCameraMode::kImage;
    if (image_mode && !scene.effects.AnyImageStage()) {
      throw Error(
          "fake camera: image mode needs a scene that renders frames (an image effect on); " +
          scene.source + " gives exact peaks only (use --mode profile)");
    }
    const auto count = static_cast<std::size_t>(frame_count);
    frame_times_s.assign(count, 0.0);
    frame_sweeps.assign(count, 0);
    if (image_mode)
      images.assign(count, {});
    else {
      peak_rows.assign(count, {});
      peaks_dropped.assign(count, 0);
    }
    const int threads = options.threads > 0 ? options.threads : omp_get_max_threads();
    std::exception_ptr failure;
    std::atomic<std::int64_t> done{0};
#pragma omp parallel for num_threads(threads) schedule(dynamic, 1)
    for (std::int64_t i = 0; i < frame_count; ++i) {
      try {
        sim::SimulatedFrame f = simulator.Frame(i);
        const MirrorCommand expected = driver.CommandOf(static_cast<std::uint64_t>(i));
        if (f.command != expected.command || f.sweep != expected.sweep) {
          throw Error("fake camera: frame " + std::to_string(i) +
                      " was simulated with mirror command " + std::to_string(f.command) +
                      " (sweep " + std::to_string(f.sweep) + ") but the mirror driver gives " +
                      std::to_string(expected.command) + " (sweep " +
                      std::to_string(expected.sweep) + ")");
        }
        const auto k = static_cast<std::size_t>(i);
        frame_times_s[k] = f.time_s;
        frame_sweeps[k] = f.sweep;
        if (image_mode) {
          if (!f.image)
            throw Error("fake camera: frame " + std::to_string(i) + " was not rendered");
          images[k] = std::move(*f.image);
        } else {
          std::vector<std::uint8_t> payload(profile_layout.payload_bytes());
          const ProfileEncodeResult r = EncodeProfile(profile_layout, f.peaks_px, {}, payload);
          payload.resize(static_cast<std::size_t>(profile_layout.peak_rows) * profile_layout.lines *
                         2);
          peak_rows[k] = std::move(payload);
          peaks_dropped[k] = r.peaks_dropped;
        }
      } catch (...) {
#pragma omp critical(uwscan_fake_camera_failure)
        if (!failure) failure = std::current_exception();
      }
      const std::int64_t finished = ++done;
      if (progress && omp_get_thread_num() == 0)
        progress(static_cast<double>(finished) / frame_count);
    }
    if (failure) std::rethrow_exception(failure);
    if (progress) progress(1.0);
    frame_rate = options.frame_rate_hz > 0.0 ? options.frame_rate_hz : driver.trigger_rate_hz();
    frame_rate = std::min(frame_rate, 1000.0);
  }

  void Start() {
    // Aravis's fake camera reads its GenICam description from a file.
    char folder_template[] = "/tmp/uwscan-fake-camera-XXXXXX";
    const char* folder = mkdtemp(folder_template);
    if (folder == nullptr) throw Error("fake camera: cannot create a temporary folder in /tmp");
    const std::filesystem::path xml = std::filesystem::path(folder) / "uwscan_fake_camera.xml";
    {
      std::ofstream out(xml, std::ios::binary);
      out << kFakeCameraGenicamXml;
      if (!out) throw Error("fake camera: cannot write " + xml.string());
    }
    gv = arv_gv_fake_camera_new_full(options.address.c_str(), options.serial.c_str(), xml.c_str());
    std::error_code ignored;
    std::filesystem::remove_all(folder, ignored);
    if (gv == nullptr || !arv_gv_fake_camera_is_running(gv)) {
      if (gv != nullptr) g_clear_object(&gv);
      throw Error(
          "fake camera: cannot answer on " + options.address +
          " (no interface with that address or name, or the GigE Vision port 3956 is taken)");
    }
    ArvFakeCamera* camera = arv_gv_fake_camera_get_fake_camera(gv);
    WriteString(camera, kManufacturerName, "uwscan", 32);
    WriteString(camera, kModelName, "uwscan simulated laser camera", 32);
    const bool image_mode = !images.empty();
    const guint32 width =
        image_mode ? static_cast<guint32>(image_width) : static_cast<guint32>(profile_layout.lines);
    const guint32 height = image_mode ? static_cast<guint32>(image_height + 1)
                                      : static_cast<guint32>(profile_layout.peak_rows + 1);
    arv_fake_camera_write_register(camera, ARV_FAKE_CAMERA_REGISTER_SENSOR_WIDTH, width);
    arv_fake_camera_write_register(camera, ARV_FAKE_CAMERA_REGISTER_SENSOR_HEIGHT, height);
    arv_fake_camera_write_register(camera, ARV_FAKE_CAMERA_REGISTER_WIDTH, width);
    arv_fake_camera_write_register(camera, ARV_FAKE_CAMERA_REGISTER_HEIGHT, height);
    const bool sixteen = !image_mode || images.front().format == PixelFormat::kMono16;
    arv_fake_camera_write_register(camera, ARV_FAKE_CAMERA_REGISTER_PIXEL_FORMAT,
                                   sixteen ? ARV_PIXEL_FORMAT_MONO_16 : ARV_PIXEL_FORMAT_MONO_8);
    arv_fake_camera_write_register(camera, ARV_FAKE_CAMERA_REGISTER_ACQUISITION_FRAME_PERIOD_US,
                                   static_cast<guint32>(std::llround(1e6 / frame_rate)));
    arv_fake_camera_set_trigger_frequency(camera, frame_rate);
    arv_fake_camera_write_register(camera, kRegPayloadMode, image_mode ? 0 : 1);
    arv_fake_camera_write_register(camera, kRegStripeAxis,
                                   profile_layout.axis == StripeAxis::kRows ? 1 : 0);
    arv_fake_camera_write_register(camera, kRegPeakRows,
                                   static_cast<guint32>(profile_layout.peak_rows));
    arv_fake_camera_write_register(camera, kRegImageWidth, static_cast<guint32>(image_width));
    arv_fake_camera_write_register(camera, kRegImageHeight, static_cast<guint32>(image_height));
    arv_fake_camera_set_fill_pattern(camera, &Impl::Fill, this);
    // A wake-up well inside a frame period (see FakeCameraWakeup), at most every 0.5 ms.
    const int wakeup_period_us = static_cast<int>(std::clamp(0.25e6 / frame_rate, 250.0, 500.0));
    constexpr guint32 kCurrentIpAddressRegister = 0x0024;  // GigE Vision bootstrap register
    guint32 ip = 0;
    arv_fake_camera_read_register(camera, kCurrentIpAddressRegister, &ip);
    wakeup = std::make_unique<FakeCameraWakeup>(ip, wakeup_period_us);
  }
};

FakeCamera::FakeCamera(const sim::Simulator& simulator, const FakeCameraOptions& options,
                       const std::function<void(double)>& progress)
    : impl_(std::make_unique<Impl>(simulator)) {
  options.Check();
  impl_->options = options;
  impl_->Prepare(simulator, progress);
  impl_->Start();
}

FakeCamera::~FakeCamera() = default;

FakeCameraStatistics FakeCamera::statistics() const {
  FakeCameraStatistics s;
  s.frames_sent = impl_->sent.load();
  s.frames_dropped = impl_->dropped.load();
  s.peaks_dropped = impl_->peaks_lost.load();
  return s;
}

std::size_t FakeCamera::payload_bytes() const {
  if (!impl_->images.empty()) {
    ImageLayout layout{impl_->image_width, impl_->image_height, impl_->images.front().format};
    return layout.payload_bytes();
  }
  return impl_->profile_layout.payload_bytes();
}

double FakeCamera::frame_rate_hz() const { return impl_->frame_rate; }

}  // namespace uwscan::scanner::acquisition
