#include "ros/bag/bag_export.hpp"

#include <cmath>
#include <ctime>
#include <fstream>
#include <nlohmann/json.hpp>

#include "mapping/log/dive_log.hpp"
#include "ros/bag/recognition_export.hpp"
#include "ros/bag/report_export.hpp"
#include "ros/bridge/bag_file.hpp"
#include "ros/conversions/dive_description.hpp"
#include "ros/conversions/frame_image.hpp"
#include "scanner/common/error.hpp"

namespace uwscan::ros {
namespace {

// Times below this are not Unix times (2001-09-09): a dive counted from its start.
constexpr double kUnixTimeFloor_s = 1e9;

// "2024-05-01T12:34:56Z" as Unix seconds; 0 when it does not parse.
double UnixSeconds(const std::string& utc) {
  std::tm tm{};
  if (::strptime(utc.c_str(), "%Y-%m-%dT%H:%M:%SZ", &tm) == nullptr) return 0.0;
  return static_cast<double>(::timegm(&tm));
}

// 0 for a log in Unix time, else its creation time (whole seconds).
double TimeOrigin(const mapping::DiveLogReader& reader) {
  double first_s = reader.frame_count() > 0 ? reader.ReadFrame(0).time_s : kUnixTimeFloor_s;
  const std::vector<mapping::NavigationRecord> navigation = reader.ReadNavigation();
  if (!navigation.empty()) first_s = std::min(first_s, navigation.front().time_s);
  if (first_s >= kUnixTimeFloor_s) return 0.0;
  const double created = UnixSeconds(reader.header().created_utc);
  return created > 0.0 ? created : kUnixTimeFloor_s;
}

std::string ReportKind(const std::filesystem::path& path) {
  std::ifstream in(path);
  try {
    return nlohmann::json::parse(in).value("kind", "");
  } catch (const nlohmann::json::exception&) {
    throw Error(path.string() + ": neither a dive log (SQLite) nor a JSON report");
  }
}

// The dive log a report was made from: a map report's "log", a recognition report's scan when
// that is a log; empty for anything else.
std::filesystem::path LogOfReport(const std::filesystem::path& input) {
  std::ifstream in(input);
  const nlohmann::json report = nlohmann::json::parse(in, nullptr, /*allow_exceptions=*/false);
  if (!report.is_object()) return {};
  std::filesystem::path log;
  if (report.value("kind", "") == "map_report" && report.contains("log") &&
      report["log"].is_string()) {
    log = report["log"].get<std::string>();
  }
  if (report.value("kind", "") == "recognition_report" && report.contains("scan") &&
      report["scan"].is_string()) {
    log = input.parent_path() / report["scan"].get<std::string>();
  }
  return std::filesystem::is_regular_file(log) && mapping::IsSqliteFile(log)
             ? log
             : std::filesystem::path();
}

// The origin of the first dive log, else of the log the first report names.
double TimeOriginOf(const std::vector<std::filesystem::path>& inputs) {
  for (const std::filesystem::path& input : inputs) {
    if (mapping::IsSqliteFile(input)) return TimeOrigin(mapping::DiveLogReader(input));
  }
  for (const std::filesystem::path& input : inputs) {
    if (const std::filesystem::path log = LogOfReport(input); !log.empty())
      return TimeOrigin(mapping::DiveLogReader(log));
  }
  return kUnixTimeFloor_s;
}

ImageMessage FrameMessage(const mapping::FrameRecord& frame,
                          const scanner::acquisition::ProfileLayout& layout, double origin_s,
                          const RosFrames& frames) {
  return FrameToImage(frame, layout, static_cast<std::uint64_t>(frame.index),
                      Header{origin_s + frame.time_s, frames.camera});
}

void WriteNavigation(const mapping::NavigationRecord& nav, double origin_s,
                     const BagExportOptions& o, BagWriter& bag) {
  const Header header{origin_s + nav.time_s, o.frames.odom};
  OdometryMessage odometry;
  odometry.header = header;
  odometry.child_frame_id = o.frames.base_link;
  odometry.pose = nav.T_W_V;
  bag.Write(o.topics.odometry, odometry);
  bag.Write(o.topics.tf, std::vector<TransformMessage>{{header, o.frames.base_link, nav.T_W_V}},
            header.stamp_s);
}

// The profile layout that carries every frame of the log whole.
scanner::acquisition::ProfileLayout LayoutOf(const mapping::DiveLogReader& reader) {
  ProfileLayoutFinder finder;
  reader.ForEachFrame(
      [&](const mapping::FrameRecord& f, const mapping::GroundTruthRecord*) {
        if (!f.image) finder.Add(f);
      },
      false);
  return finder.Layout(reader.header().scanner.camera().camera);
}

void ExportDive(const std::filesystem::path& log, double origin_s, const BagExportOptions& o,
                BagWriter& bag, BagExportSummary& summary) {
  const mapping::DiveLogReader reader(log);
  if (reader.frame_count() == 0) throw Error(log.string() + ": the log holds no frames");
  summary.layout = LayoutOf(reader);
  const double start_s = origin_s + reader.ReadFrame(0).time_s;
  DiveDescription description{reader.header(), origin_s};
  description.header.producer = o.producer;
  bag.Write(o.topics.dive, StringMessage{DiveDescriptionToYaml(description)}, start_s, true);
  const Eigen::Isometry3d T_V_C = reader.vehicle_mount().value_or(Eigen::Isometry3d::Identity());
  bag.Write(o.topics.tf_static,
            std::vector<TransformMessage>{{{start_s, o.frames.base_link}, o.frames.camera, T_V_C}},
            start_s);
  reader.ForEachFrame(
      [&](const mapping::FrameRecord& f, const mapping::GroundTruthRecord*) {
        bag.Write(o.topics.frames, FrameMessage(f, summary.layout, origin_s, o.frames));
        ++summary.frames;
        if (f.image) ++summary.images;
      },
      false);
  const std::vector<mapping::NavigationRecord> navigation = reader.ReadNavigation();
  for (const mapping::NavigationRecord& nav : navigation) WriteNavigation(nav, origin_s, o, bag);
  summary.navigation += static_cast<std::int64_t>(navigation.size());
}

void ExportInput(const std::filesystem::path& input, const BagExportOptions& o, BagWriter& bag,
                 BagExportSummary& summary) {
  if (mapping::IsSqliteFile(input))
    return ExportDive(input, summary.time_origin_s, o, bag, summary);
  const std::string kind = ReportKind(input);
  if (kind == "map_report") {
    const ReportExportSummary r = ExportMapReport(input, summary.time_origin_s, o, bag);
    summary.anchors += r.anchors;
    summary.map_points += r.map_points;
  } else if (kind == "recognition_report") {
    const RecognitionExportSummary r =
        ExportRecognitionReport(input, summary.time_origin_s, o, bag);
    summary.scan_points += r.scan_points;
    summary.objects += r.objects;
    summary.grasps += r.grasps;
  } else {
    throw Error(input.string() +
                ": a JSON file that is neither a map nor a recognition report (kind '" + kind +
                "')");
  }
}

}  // namespace

BagExportSummary ExportToBag(const std::vector<std::filesystem::path>& inputs,
                             const std::filesystem::path& bag_path,
                             const BagExportOptions& options) {
  for (const std::filesystem::path& input : inputs) {
    if (!std::filesystem::is_regular_file(input)) throw Error(input.string() + ": no such file");
  }
  BagExportSummary summary;
  summary.time_origin_s = TimeOriginOf(inputs);
  BagWriter bag(bag_path.string());
  try {
    for (const std::filesystem::path& input : inputs) ExportInput(input, options, bag, summary);
    bag.Close();
    return summary;
  } catch (...) {
    try {
      bag.Close();
    } catch (...) {
    }
    std::filesystem::remove(bag_path);
    throw;
  }
}

}  // namespace uwscan::ros
