#pragma once

#include "mapping/reconstruction/reconstruction.hpp"
#include "perception/recognition/recognition_report.hpp"
#include "viewer/scene/scene.hpp"

// Drawing the recognition report `uwscan recognize --json` writes (issue 11; read by
// perception/recognition/recognition_report).
namespace uwscan::viewer {

using perception::IsRecognitionReport;
using perception::ReadRecognitionReport;
using perception::RecognitionReport;
using perception::ReportedObject;

// The scan (sensor frame) with each recognised segment's points carrying its object's index
// (-1 for planes, unsegmented points and unknown segments), each recognised object's model from the
// database placed at its pose with the same index (so colouring by object pairs a segment with its
// model), a label with its id and score in front of it, and its grasp frames. A scan that is a dive
// log is triangulated as `recognize` did (the scanner's default method, whatever `log_options` say;
// their table cache is used). Throws uwscan::Error naming the report when its scan
// or database cannot be read, the scan no longer has the report's point count, or the database
// lacks a recognised object.
void AddRecognitionReport(const RecognitionReport& report,
                          const mapping::ReconstructionOptions& log_options, Scene& scene);

}  // namespace uwscan::viewer
