#include "mapping/inspection/camera_reader.hpp"

#include <chrono>

namespace uwscan::mapping {

namespace acq = scanner::acquisition;

ReadSummary ReadFrames(acq::FrameSource& source, CameraFrameDecoder& decoder,
                       const ReadLimits& limits, const ReadCallbacks& callbacks) {
  const bool software_trigger = source.settings().trigger == acq::TriggerMode::kSoftware;
  ReadSummary summary;
  source.Start();
  if (software_trigger) source.SoftwareTrigger();
  double last_status = 0.0;
  std::size_t gaps_reported = 0;
  while (!(callbacks.stop_requested && callbacks.stop_requested())) {
    if (limits.frames > 0 && summary.frames >= limits.frames) break;
    if (limits.seconds > 0.0 && source.ElapsedSeconds() >= limits.seconds) break;
    std::optional<acq::AcquiredFrame> frame = source.Next(std::chrono::milliseconds(100));
    const double now = source.ElapsedSeconds();
    summary.source = source.statistics();
    while (gaps_reported < summary.source.gaps.size() &&
           summary.source.gaps[gaps_reported].resumed_at_s >= 0.0) {
      if (callbacks.gap) callbacks.gap(summary.source.gaps[gaps_reported]);
      ++gaps_reported;
    }
    if (callbacks.status && now - last_status >= 1.0) {
      callbacks.status(summary, now);
      last_status = now;
    }
    if (!frame) continue;
    if (software_trigger) source.SoftwareTrigger();
    std::optional<FrameRecord> record = decoder.Decode(*frame);
    if (!record) {
      ++summary.undecodable;
      continue;
    }
    summary.peaks += static_cast<std::int64_t>(record->peaks_px.size());
    callbacks.consume(std::move(*record), *frame);
    ++summary.frames;
  }
  summary.seconds = source.ElapsedSeconds();
  source.Stop();
  summary.source = source.statistics();
  for (std::size_t i = gaps_reported; i < summary.source.gaps.size(); ++i) {
    if (callbacks.gap) callbacks.gap(summary.source.gaps[i]);
  }
  return summary;
}

}  // namespace uwscan::mapping
