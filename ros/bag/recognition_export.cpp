#include "ros/bag/recognition_export.hpp"

#include <limits>

#include "mapping/log/dive_log.hpp"
#include "mapping/reconstruction/scan_file.hpp"
#include "perception/recognition/object_database.hpp"
#include "perception/recognition/recognition_report.hpp"
#include "ros/conversions/object_messages.hpp"

namespace uwscan::ros {
namespace {

// As mapping::ReadScanFile tells a dive log from a cloud file.
bool IsDiveLog(const std::filesystem::path& path) { return path.extension() == ".db"; }

// The middle of the sweep's frames, in the log's time (ScanFile gives a log's points there).
double SweepMiddle_s(const std::filesystem::path& log, const std::optional<int>& sweep) {
  double first_s = std::numeric_limits<double>::infinity(), last_s = -first_s;
  mapping::DiveLogReader(log).ForEachFrame(
      [&](const mapping::FrameRecord& f, const mapping::GroundTruthRecord*) {
        if (sweep && f.sweep != *sweep) return;
        first_s = std::min(first_s, f.time_s);
        last_s = std::max(last_s, f.time_s);
      },
      false);
  return 0.5 * (first_s + last_s);
}

CloudMessage ScanCloud(const perception::RecognitionReport& report, const Header& header) {
  // `recognize` triangulates a dive log with the scanner's default method, as here.
  mapping::ReconstructionOptions options;
  options.sweep = report.scan_sweep;
  const perception::PointCloud scan =
      mapping::ReadScanFile(report.scan, options, mapping::ReportedScanFrame(report)).cloud;
  CloudMessage message;
  message.header = header;
  message.points.reserve(scan.size());
  for (std::size_t i = 0; i < scan.size(); ++i)
    message.points.push_back(scan.Point(i).cast<float>());
  return message;
}

}  // namespace

RecognitionExportSummary ExportRecognitionReport(const std::filesystem::path& path, double origin_s,
                                                 const BagExportOptions& o, BagWriter& bag) {
  const perception::RecognitionReport report = perception::ReadRecognitionReport(path);
  const double stamp_s =
      origin_s + (IsDiveLog(report.scan) ? SweepMiddle_s(report.scan, report.scan_sweep) : 0.0);
  const Header header{stamp_s, o.frames.camera};
  const CloudMessage scan = ScanCloud(report, header);
  const perception::ObjectDatabase db = perception::ObjectDatabase::Load(report.database);
  const ObjectMessages messages =
      MakeObjectMessages(report.objects, db, header, kDefaultModelMarkerPoints);
  bag.Write(o.topics.sweeps, scan);
  bag.Write(o.topics.objects, messages.markers, stamp_s);
  for (const PoseMessage& pose : messages.poses) bag.Write(o.topics.object_poses, pose);
  bag.Write(o.topics.grasps, messages.grasps);
  RecognitionExportSummary summary;
  summary.scan_points = static_cast<std::int64_t>(scan.points.size());
  summary.objects = static_cast<std::int64_t>(messages.poses.size());
  summary.grasps = static_cast<std::int64_t>(messages.grasps.poses.size());
  return summary;
}

}  // namespace uwscan::ros
