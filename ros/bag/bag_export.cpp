#include "ros/bag/bag_export.hpp"

#include <cmath>
#include <ctime>

#include "mapping/log/dive_log.hpp"
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

double TimeOrigin(const mapping::DiveLogReader& reader, double first_time_s) {
  if (first_time_s >= kUnixTimeFloor_s) return 0.0;
  const double created = UnixSeconds(reader.header().created_utc);
  return created > 0.0 ? created : kUnixTimeFloor_s;
}

ImageMessage FrameMessage(const mapping::FrameRecord& frame, const scanner::acquisition::ProfileLayout& layout,
                          double origin_s, const RosFrames& frames) {
  return FrameToImage(frame, layout, static_cast<std::uint64_t>(frame.index),
                      Header{origin_s + frame.time_s, frames.camera});
}

void WriteNavigation(const mapping::NavigationRecord& nav, double origin_s, const BagExportOptions& o, BagWriter& bag) {
  const Header header{origin_s + nav.time_s, o.frames.odom};
  OdometryMessage odometry;
  odometry.header = header;
  odometry.child_frame_id = o.frames.base_link;
  odometry.pose = nav.T_W_V;
  bag.Write(o.topics.odometry, odometry);
  bag.Write(o.topics.tf, std::vector<TransformMessage>{{header, o.frames.base_link, nav.T_W_V}}, header.stamp_s);
}

BagExportSummary Export(const mapping::DiveLogReader& reader, BagWriter& bag, const BagExportOptions& o) {
  BagExportSummary summary;
  ProfileLayoutFinder finder;
  std::optional<double> first_time_s;
  reader.ForEachFrame(
      [&](const mapping::FrameRecord& f, const mapping::GroundTruthRecord*) {
        if (!first_time_s) first_time_s = f.time_s;
        if (!f.image) finder.Add(f);
      },
      false);
  const std::vector<mapping::NavigationRecord> navigation = reader.ReadNavigation();
  if (!first_time_s) throw Error(reader.path().string() + ": the log holds no frames");
  summary.layout = finder.Layout(reader.header().scanner.camera().camera);
  summary.time_origin_s = TimeOrigin(reader, std::min(*first_time_s, navigation.empty() ? *first_time_s
                                                                                        : navigation.front().time_s));
  const double start_s = summary.time_origin_s + *first_time_s;

  DiveDescription description{reader.header(), summary.time_origin_s};
  description.header.producer = o.producer;
  bag.Write(o.topics.dive, StringMessage{DiveDescriptionToYaml(description)}, start_s, true);
  const Eigen::Isometry3d T_V_C = reader.vehicle_mount().value_or(Eigen::Isometry3d::Identity());
  bag.Write(o.topics.tf_static, std::vector<TransformMessage>{{{start_s, o.frames.base_link}, o.frames.camera, T_V_C}},
            start_s);
  reader.ForEachFrame(
      [&](const mapping::FrameRecord& f, const mapping::GroundTruthRecord*) {
        bag.Write(o.topics.frames, FrameMessage(f, summary.layout, summary.time_origin_s, o.frames));
        ++summary.frames;
        if (f.image) ++summary.images;
      },
      false);
  for (const mapping::NavigationRecord& nav : navigation) WriteNavigation(nav, summary.time_origin_s, o, bag);
  summary.navigation = static_cast<std::int64_t>(navigation.size());
  return summary;
}

}  // namespace

BagExportSummary ExportDiveLog(const std::filesystem::path& log, const std::filesystem::path& bag_path,
                               const BagExportOptions& options) {
  const mapping::DiveLogReader reader(log);
  BagWriter bag(bag_path.string());
  try {
    BagExportSummary summary = Export(reader, bag, options);
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
