#include "bench/scanner/simulation_benchmark.hpp"

#include <algorithm>
#include <chrono>
#include <functional>
#include <limits>
#include <memory>
#include <utility>

#include "scanner/common/option_checks.hpp"
#include "scanner/sim/scene.hpp"
#include "scanner/sim/simulator.hpp"

namespace uwscan::bench {
namespace {

using scanner::sim::Scene;
using scanner::sim::SimulationEffects;
using Clock = std::chrono::steady_clock;

SimulationEffects AllOff() {
  SimulationEffects e;
  e.refraction = e.lens_distortion = e.occlusion = false;
  return e;
}

// Each effect switched on alone, by name.
std::vector<std::pair<std::string, std::function<void(SimulationEffects&)>>> Effects(bool mems) {
  std::vector<std::pair<std::string, std::function<void(SimulationEffects&)>>> list = {
      {"refraction", [](SimulationEffects& e) { e.refraction = true; }},
      {"lens_distortion", [](SimulationEffects& e) { e.lens_distortion = true; }},
      {"occlusion", [](SimulationEffects& e) { e.occlusion = true; }},
      {"motion", [](SimulationEffects& e) { e.motion = true; }},
      {"navigation_drift", [](SimulationEffects& e) { e.navigation_drift.on = true; }},
      {"image", [](SimulationEffects& e) { e.image.on = true; }},
      {"beam", [](SimulationEffects& e) { e.beam.on = true; }},
      {"sensor_noise", [](SimulationEffects& e) { e.sensor_noise.on = true; }},
      {"speckle", [](SimulationEffects& e) { e.speckle.on = true; }},
      {"attenuation", [](SimulationEffects& e) { e.attenuation = true; }},
      {"backscatter", [](SimulationEffects& e) { e.backscatter.on = true; }},
      {"ambient", [](SimulationEffects& e) { e.ambient.on = true; }},
  };
  if (mems)
    list.emplace_back("mirror_dynamics", [](SimulationEffects& e) { e.mirror_dynamics = true; });
  return list;
}

// Every effect off, every parameter away from its default: what an off stage must not cost.
SimulationEffects OffWithParameters() {
  SimulationEffects e = AllOff();
  e.navigation_drift.position_walk_m_per_sqrt_s = 0.01;
  e.image.peak_level = 250.0;
  e.image.blur_sigma_px = 1.5;
  e.beam.diameter_m = 0.003;
  e.sensor_noise.read_sigma = 5.0;
  e.speckle.contrast = 0.5;
  e.backscatter.level = 40.0;
  e.ambient.level = 30.0;
  return e;
}

// Times every row's frames in round-robin passes (row 1, row 2, ..., then again), so that a
// drift of the shared machine's speed does not favour the rows measured first or last; each row
// keeps its fastest pass.
std::vector<EffectCost> TimeRows(const Scene& base,
                                 const std::vector<std::pair<std::string, SimulationEffects>>& rows,
                                 const SimulationBenchOptions& o,
                                 const std::function<void(double)>& done) {
  std::vector<std::unique_ptr<scanner::sim::Simulator>> simulators;
  for (const auto& row : rows) {
    Scene scene = base;
    scene.effects = row.second;
    simulators.push_back(std::make_unique<scanner::sim::Simulator>(scene));
  }
  const std::int64_t count = simulators.front()->frame_count();
  std::vector<std::int64_t> indices;
  for (int k = 0; k < o.frames; ++k) indices.push_back(count * k / o.frames);
  std::vector<EffectCost> costs(rows.size());
  std::vector<double> best(rows.size(), std::numeric_limits<double>::infinity());
  for (int pass = 0; pass <= o.repeats; ++pass) {  // pass 0 warms up (caches, lazy set-up)
    for (size_t r = 0; r < rows.size(); ++r) {
      std::int64_t peaks = 0;
      const Clock::time_point start = Clock::now();
      for (const std::int64_t i : indices) peaks += std::ssize(simulators[r]->Frame(i).peaks_px);
      const double seconds = std::chrono::duration<double>(Clock::now() - start).count();
      if (pass > 0) best[r] = std::min(best[r], seconds);
      costs[r].peaks = peaks;
      done((pass * rows.size() + r + 1.0) / ((o.repeats + 1.0) * rows.size()));
    }
  }
  for (size_t r = 0; r < rows.size(); ++r) {
    costs[r].effect = rows[r].first;
    costs[r].ms_per_frame = 1e3 * best[r] / static_cast<double>(indices.size());
    costs[r].ratio_to_none = best[r] / best[0];
  }
  return costs;
}

}  // namespace

void SimulationBenchOptions::Check() const {
  const OptionChecks check("SimulationBenchOptions");
  check.AtLeast("frames", frames, 1);
  check.AtLeast("repeats", repeats, 1);
}

SimulationBenchResult RunSimulationBenchmark(const SimulationBenchOptions& o,
                                             const Progress& progress) {
  o.Check();
  SimulationBenchResult result;
  result.frames = o.frames;
  for (const auto& [name, file] :
       {std::pair{"galvo", "default.yaml"}, std::pair{"mems", "mems_plane.yaml"}}) {
    const Scene scene = scanner::sim::LoadScene(o.data_dir / "scenes" / file);
    const bool mems = std::string(name) == "mems";
    std::vector<std::pair<std::string, SimulationEffects>> rows = {{"none", AllOff()}};
    SimulationEffects all = AllOff();
    for (const auto& [effect, switch_on] : Effects(mems)) {
      SimulationEffects alone = AllOff();
      switch_on(alone);
      switch_on(all);
      rows.emplace_back(effect, alone);
    }
    rows.emplace_back("off_with_parameters", OffWithParameters());
    rows.emplace_back("all", all);
    for (EffectCost& cost : TimeRows(scene, rows, o, [&, &scene_name = name](double f) {
           if (progress) progress(std::string("simulation ") + scene_name, f);
         })) {
      cost.scene = name;
      result.rows.push_back(cost);
    }
    if (progress) progress(std::string("simulation ") + name, 1.0);
  }
  return result;
}

}  // namespace uwscan::bench
