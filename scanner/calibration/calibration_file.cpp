#include "scanner/calibration/calibration_file.hpp"

#include <chrono>
#include <ctime>
#include <fstream>
#include <system_error>

#include "scanner/common/error.hpp"

namespace uwscan::scanner::calibration {

Scanner ScannerInMedium(Scanner scanner, const std::optional<double>& water_index) {
  if (!water_index) return scanner;
  scanner.camera().viewport.n_water = *water_index;
  scanner.laser_viewport().n_water = *water_index;
  RefitSampledFunctions(&scanner);
  return scanner;
}

std::string NowUtc() {
  const std::time_t now = std::chrono::system_clock::to_time_t(std::chrono::system_clock::now());
  std::tm tm{};
  gmtime_r(&now, &tm);
  char text[32];
  std::strftime(text, sizeof(text), "%Y-%m-%dT%H:%M:%SZ", &tm);
  return text;
}

}  // namespace uwscan::scanner::calibration
