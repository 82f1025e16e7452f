#pragma once

#include <string>

namespace uwscan::scanner {

enum class ScannerKind { kGalvo, kMems };

const char* ToString(ScannerKind kind);  // "galvo", "mems"

// Galvanometer sweep: one frame per mirror step from step_min to step_max every step_stride.
struct GalvoScan {
  int step_min = -100;
  int step_max = 100;
  int step_stride = 1;
  double frame_rate_hz = 339.0;  // seed camera in laser-detection mode

  int frames_per_sweep() const { return (step_max - step_min) / step_stride + 1; }
  int StepOfFrame(int frame_in_sweep) const { return step_min + frame_in_sweep * step_stride; }
  void Check() const;
};

// MEMS scan pattern (seed 001): `lines` lines of `waypoints_per_line` waypoints spread evenly
// over fov_fraction of the projection functions' field of view; one frame per line.
struct MemsScan {
  int lines = 500;
  int waypoints_per_line = 50;
  double waypoint_rate_hz = 3500.0;  // DAC update rate of the mirror driver
  double fov_fraction_x = 0.9;  // (0, 1]; the FoV rectangle's corners lie beyond the drive range
  double fov_fraction_y = 0.9;  // (0, 1]

  void Check() const;
};

// How a dive was scanned: which scanner and which pattern. Stored in dive logs beside the
// scanner configuration, so that a log reconstructs without the scene it came from.
struct ScanPattern {
  ScannerKind kind = ScannerKind::kGalvo;
  GalvoScan galvo;
  MemsScan mems;

  int frames_per_sweep() const {
    return kind == ScannerKind::kGalvo ? galvo.frames_per_sweep() : mems.lines;
  }
  void Check() const;
};

std::string ScanPatternToYaml(const ScanPattern& pattern);
// Throws uwscan::Error naming source:line and the field.
ScanPattern ParseScanPattern(const std::string& yaml_text, const std::string& source_name);

}  // namespace uwscan::scanner
