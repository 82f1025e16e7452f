#include "mapping/log/dive_log_format.hpp"

#include <string>
#include <utility>

#include "mapping/log/dive_log.hpp"
#include "scanner/common/option_checks.hpp"

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
  const OptionChecks check("NavigationNoise");
  check.NonNegative("position_walk_m_per_sqrt_s", position_walk_m_per_sqrt_s, "m/sqrt(s)");
  check.NonNegative("heading_walk_rad_per_sqrt_s", heading_walk_rad_per_sqrt_s, "rad/sqrt(s)");
  check.NonNegative("speed_scale_sigma", speed_scale_sigma);
  check.NonNegative("heading_bias_sigma_rad", heading_bias_sigma_rad, "rad");
  check.NonNegative("depth_sigma_m", depth_sigma_m, "m");
  check.NonNegative("roll_pitch_sigma_rad", roll_pitch_sigma_rad, "rad");
}

}  // namespace uwscan::mapping
