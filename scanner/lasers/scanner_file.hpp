#pragma once

#include <filesystem>
#include <string>

#include "scanner/lasers/scanner.hpp"

namespace uwscan::scanner {

// The scanner file (format in data/README.md): a galvanometer scanner has `laser:`, a MEMS
// scanner `mems:` (and optionally `projection_functions:`); both have `camera:`,
// `camera_viewport:`, `laser_viewport:` and optionally `calibration:` records. These are the
// only functions that read or write scanner YAML; everything else takes a Scanner.

// Throws uwscan::Error naming the source, line and field on anything missing, malformed,
// unknown or out of range.
Scanner ParseScanner(const std::string& yaml_text, const std::string& source_name);
Scanner LoadScanner(const std::filesystem::path& path);

// The whole file, every number with round-trip precision (17 significant digits):
// ParseScanner(ScannerToYaml(s)) holds the same values as s (poses are written as quaternions:
// their rotations come back to within a bit or two). A MEMS scanner's projection
// functions are written only when they came from a file (a calibration): fitted ones are fitted
// again, identically, on reading. `comment` (optional) becomes the first lines, each after "# ".
std::string ScannerToYaml(const Scanner& scanner, const std::string& comment = "");

// The scanners shipped in data/scanners/galvo_default.yaml and mems_default.yaml, compiled in.
Scanner DefaultScanner(ScannerKind kind);

}  // namespace uwscan::scanner
