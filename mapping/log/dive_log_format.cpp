#include "mapping/log/dive_log_format.hpp"

#include <cmath>
#include <string>
#include <utility>

#include "mapping/log/dive_log.hpp"
#include "scanner/common/error.hpp"

namespace uwscan::mapping::dive_log_format {

std::string Quoted(const std::filesystem::path& path) {
  // Appended piecewise: GCC 12 warns falsely (-Wrestrict) on "'" + std::string.
  std::string quoted(1, '\'');
  quoted.append(path.string());
  quoted.push_back('\'');
  return quoted;
}

std::string LogName(const std::filesystem::path& path) { return "dive log " + Quoted(path); }

std::string FrameName(std::int64_t index) { return "frame " + std::to_string(index); }

void SwapBytePairs(std::vector<std::uint8_t>& bytes) {
  for (std::size_t i = 0; i + 1 < bytes.size(); i += 2) std::swap(bytes[i], bytes[i + 1]);
}

}  // namespace uwscan::mapping::dive_log_format

namespace uwscan::mapping {

void NavigationNoise::Check() const {
  const std::pair<const char*, double> fields[] = {
      {"position_walk_m_per_sqrt_s", position_walk_m_per_sqrt_s},
      {"heading_walk_rad_per_sqrt_s", heading_walk_rad_per_sqrt_s},
      {"speed_scale_sigma", speed_scale_sigma},
      {"heading_bias_sigma_rad", heading_bias_sigma_rad},
      {"depth_sigma_m", depth_sigma_m},
      {"roll_pitch_sigma_rad", roll_pitch_sigma_rad}};
  for (const auto& [field, value] : fields) {
    if (!(std::isfinite(value) && value >= 0.0)) {
      throw Error(std::string("navigation noise ") + field + ": " + std::to_string(value) +
                  ", expected a finite value >= 0");
    }
  }
}

}  // namespace uwscan::mapping
