#include <memory>

#include "scanner/lasers/galvo_scanner_model.hpp"
#include "scanner/sim/light_source.hpp"

namespace uwscan::scanner::sim {
namespace {

class GalvoLightSource final : public LightSource {
 public:
  GalvoLightSource(GalvoScannerModel model, const GalvoScan& scan)
      : model_(std::move(model)), scan_(scan) {
    scan_.Check();
  }
  const RefractiveCamera& camera() const override { return model_.camera; }
  int frames_per_sweep() const override { return scan_.frames_per_sweep(); }
  double frame_period_s() const override { return 1.0 / scan_.frame_rate_hz; }
  int CommandOfFrame(int frame_in_sweep) const override {
    return scan_.StepOfFrame(frame_in_sweep);
  }

  LaserPath PathOfFrame(int frame_in_sweep) const override {
    auto fan =
        std::make_shared<const LaserFan>(model_.laser.FanAtStep(CommandOfFrame(frame_in_sweep)));
    LaserPath path;
    path.ray_in_water_C = [fan](double fan_tan) { return fan->RayInWater(fan_tan); };
    const double max_tan = model_.laser.MaxFanTan();
    path.s_begin = -max_tan;
    path.s_end = max_tan;
    path.samples = 513;
    return path;
  }

 private:
  GalvoScannerModel model_;
  GalvoScan scan_;
};

}  // namespace

std::unique_ptr<LightSource> MakeGalvoLightSource(const GalvoScannerModel& model,
                                                  const GalvoScan& scan) {
  return std::make_unique<GalvoLightSource>(model, scan);
}

}  // namespace uwscan::scanner::sim
