#include "scanner/lasers/scanner.hpp"

#include <algorithm>
#include <type_traits>

#include "scanner/common/error.hpp"

namespace uwscan::scanner {
namespace {

template <typename Model, typename Variant>
auto& ModelOf(Variant& model, const char* wanted) {
  if (Model* m = std::get_if<std::remove_const_t<Model>>(&model)) return *m;
  const bool mems = std::holds_alternative<MemsScannerModel>(model);
  throw Error(std::string("expected a ") + wanted + " scanner, got a " +
              (mems ? "MEMS" : "galvanometer") + " scanner");
}

}  // namespace

ScannerKind Scanner::kind() const {
  return std::holds_alternative<MemsScannerModel>(model) ? ScannerKind::kMems : ScannerKind::kGalvo;
}

const RefractiveCamera& Scanner::camera() const {
  return std::visit([](const auto& m) -> const RefractiveCamera& { return m.camera; }, model);
}
RefractiveCamera& Scanner::camera() {
  return std::visit([](auto& m) -> RefractiveCamera& { return m.camera; }, model);
}
const FlatViewport& Scanner::laser_viewport() const {
  return std::visit([](const auto& m) -> const FlatViewport& { return m.laser.viewport; }, model);
}
FlatViewport& Scanner::laser_viewport() {
  return std::visit([](auto& m) -> FlatViewport& { return m.laser.viewport; }, model);
}

const GalvoScannerModel& Scanner::galvo() const {
  return ModelOf<const GalvoScannerModel>(model, "galvanometer");
}
GalvoScannerModel& Scanner::galvo() { return ModelOf<GalvoScannerModel>(model, "galvanometer"); }
const MemsScannerModel& Scanner::mems() const {
  return ModelOf<const MemsScannerModel>(model, "MEMS");
}
MemsScannerModel& Scanner::mems() { return ModelOf<MemsScannerModel>(model, "MEMS"); }

void Scanner::Check() const {
  std::visit([](const auto& m) { m.Check(); }, model);
}

std::vector<std::string> ScannerSections(ScannerKind kind) {
  if (kind == ScannerKind::kGalvo) return {"camera", "camera_viewport", "laser", "laser_viewport"};
  return {"camera", "camera_viewport", "mems", "laser_viewport", "projection_functions"};
}

void CopySection(const Scanner& from, const std::string& section, Scanner* to) {
  const std::vector<std::string> sections = ScannerSections(from.kind());
  if (std::find(sections.begin(), sections.end(), section) == sections.end()) {
    throw Error("'" + section + "' is not a section of a " + ToString(from.kind()) +
                " scanner file");
  }
  if (from.kind() != to->kind()) {
    throw Error(std::string("cannot copy '") + section + "' from a " + ToString(from.kind()) +
                " scanner into a " + ToString(to->kind()) + " scanner");
  }
  if (section == "camera") {
    to->camera().camera = from.camera().camera;
  } else if (section == "camera_viewport") {
    to->camera().viewport = from.camera().viewport;
  } else if (section == "laser_viewport") {
    to->laser_viewport() = from.laser_viewport();
  } else if (section == "laser") {
    const FlatViewport viewport = to->laser_viewport();  // a section of its own
    to->galvo().laser = from.galvo().laser;
    to->laser_viewport() = viewport;
  } else if (section == "mems") {
    const FlatViewport viewport = to->laser_viewport();
    to->mems().laser = from.mems().laser;
    to->mems().dynamics = from.mems().dynamics;
    to->laser_viewport() = viewport;
  } else {
    if (!from.mems().functions_from_file) {
      throw Error(
          "'projection_functions': the scanner they would come from has none of its own "
          "(its functions are fitted to its laser)");
    }
    to->mems().functions = from.mems().functions;
    to->mems().functions_from_file = from.mems().functions_from_file;
  }
  if (section == "mems" || section == "laser_viewport") RefitSampledFunctions(to);
}

void RefitSampledFunctions(Scanner* scanner) {
  if (scanner->kind() == ScannerKind::kMems && !scanner->mems().functions_from_file) {
    scanner->mems().FitFunctionsToLaser();
  }
}

void SetStepRecord(Scanner* scanner, const StepRecord& record) {
  auto same = std::find_if(scanner->calibration.begin(), scanner->calibration.end(),
                           [&](const StepRecord& r) { return r.step == record.step; });
  if (same != scanner->calibration.end()) {
    *same = record;
  } else {
    scanner->calibration.push_back(record);
  }
}

}  // namespace uwscan::scanner
