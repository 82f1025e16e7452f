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

void WriteTextAtomically(const std::filesystem::path& path, const std::string& text) {
  const std::filesystem::path temp = path.string() + ".part";
  {
    std::ofstream out(temp, std::ios::binary | std::ios::trunc);
    if (!out) throw Error(path.string() + ": cannot write (folder missing or not writable)");
    out << text;
    out.flush();
    if (!out) {
      std::error_code ignored;
      std::filesystem::remove(temp, ignored);
      throw Error(path.string() + ": write failed");
    }
  }
  std::error_code ec;
  std::filesystem::rename(temp, path, ec);
  if (ec) {
    std::filesystem::remove(temp, ec);
    throw Error(path.string() + ": cannot replace the file: " + ec.message());
  }
}

}  // namespace uwscan::scanner::calibration
