#include "scanner/lasers/mems_scanner_model.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include "scanner/common/error.hpp"
#include "scanner/lasers/galvo_scanner_model.hpp"
#include "scanner/lasers/scanner_file.hpp"

namespace uwscan::scanner {
namespace {

constexpr const char* kSource = "test_mems.yaml";

std::string DefaultText() {
  const std::filesystem::path path =
      std::filesystem::path(UWSCAN_SOURCE_DIR_FOR_TESTS) / "data/scanners/mems_default.yaml";
  std::ifstream in(path);
  EXPECT_TRUE(in) << path;
  return std::string(std::istreambuf_iterator<char>(in), {});
}

// 1-based number of the line of `text` that contains `needle`.
int LineOf(const std::string& text, const std::string& needle) {
  const std::size_t at = text.find(needle);
  EXPECT_NE(at, std::string::npos) << needle;
  int line = 1;
  for (std::size_t i = 0; i < at; ++i) line += text[i] == '\n' ? 1 : 0;
  return line;
}

std::string Edited(std::string text, const std::string& from, const std::string& to) {
  const std::size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  return text.replace(at, from.size(), to);
}

// The default scanner's file with its fitted functions written out, as a calibration writes them.
std::string TextWithFunctions() {
  Scanner scanner = DefaultScanner(ScannerKind::kMems);
  scanner.mems().functions_from_file = true;
  return ScannerToYaml(scanner);
}

std::string ParseError(const std::string& text) {
  try {
    ParseScanner(text, kSource).mems();
  } catch (const Error& e) {
    return e.what();
  }
  ADD_FAILURE() << "parsed without error";
  return "";
}

TEST(MemsScannerModel, DefaultFileIsTheCompiledInDefault) {
  const MemsScannerModel compiled = DefaultMemsScannerModel();
  const MemsScannerModel loaded = LoadScanner(std::filesystem::path(UWSCAN_SOURCE_DIR_FOR_TESTS) /
                                              "data/scanners/mems_default.yaml")
                                      .mems();
  EXPECT_NO_THROW(compiled.Check());
  EXPECT_EQ(compiled.laser.emitter_origin_C, loaded.laser.emitter_origin_C);
  EXPECT_EQ(compiled.laser.T_C_M.matrix(), loaded.laser.T_C_M.matrix());
  EXPECT_EQ(compiled.functions.f3.coefficients(), loaded.functions.f3.coefficients());
  // The camera is the galvanometer default's.
  const GalvoScannerModel galvo = DefaultGalvoScannerModel();
  EXPECT_EQ(compiled.camera.camera.fx_px, galvo.camera.camera.fx_px);
  EXPECT_EQ(compiled.camera.viewport.distance_m, galvo.camera.viewport.distance_m);
  // Dynamics as in the file, and without projection_functions the ideal calibration.
  EXPECT_EQ(compiled.dynamics.resonance_hz, 1300.0);
  EXPECT_EQ(compiled.dynamics.lpf_order, 2);
  EXPECT_NEAR(compiled.functions.T_C_P.translation().z(), 1.22, 0.05);
}

TEST(MemsScannerModel, ProjectionFunctionsRoundTripExactly) {
  const MemsScannerModel model = DefaultMemsScannerModel();
  const MemsScannerModel read = ParseScanner(TextWithFunctions(), kSource).mems();
  EXPECT_TRUE(read.functions_from_file);
  const Polynomial2d* a[6] = {&model.functions.f1, &model.functions.f2, &model.functions.f3,
                              &model.functions.f4, &model.functions.f5, &model.functions.f6};
  const Polynomial2d* b[6] = {&read.functions.f1, &read.functions.f2, &read.functions.f3,
                              &read.functions.f4, &read.functions.f5, &read.functions.f6};
  for (int i = 0; i < 6; ++i) {
    // 17 significant digits read back to the same doubles.
    EXPECT_EQ(a[i]->coefficients(), b[i]->coefficients()) << "f" << i + 1;
    EXPECT_EQ(a[i]->center(), b[i]->center());
    EXPECT_EQ(a[i]->scale(), b[i]->scale());
  }
  EXPECT_EQ(model.functions.volts_min, read.functions.volts_min);
  EXPECT_EQ(model.functions.T_C_P.translation(), read.functions.T_C_P.translation());
  // The rotation passes through a quaternion: equal to rounding.
  EXPECT_LT((model.functions.T_C_P.linear() - read.functions.T_C_P.linear()).norm(), 1e-15);
}

TEST(MemsScannerModel, ErrorsNameTheLineAndTheField) {
  const std::string text = DefaultText();
  struct Case {
    std::string from, to, field, what;
  };
  const Case cases[] = {
      {"  lens_gain: 3.0", "  lens_gian: 3.0", "mems.lens_gian", "unknown field"},
      {"  max_volts: 10.0", "  max_volts: ten", "mems.max_volts", "expected a finite number"},
      {"    lpf_order: 2", "    lpf_order: 2.5", "mems.dynamics.lpf_order", "expected an integer"},
      {"    direction: [0.2113091308703498, -0.8660254037844386, -0.4531538935183251]",
       "    direction: [0.3, -0.8660254037844386, -0.4531538935183251]", "mems.emitter.direction",
       "unit vector"},
      {"  saturation: [0.5, 0.5]", "  saturation: [0.5]", "mems.saturation",
       "expected a list of 2 numbers"},
  };
  for (const Case& c : cases) {
    const std::string edited = Edited(text, c.from, c.to);
    const std::string message = ParseError(edited);
    EXPECT_NE(message.find(std::string(kSource) + ":" + std::to_string(LineOf(edited, c.to))),
              std::string::npos)
        << message;
    EXPECT_NE(message.find("'" + c.field + "'"), std::string::npos) << message;
    EXPECT_NE(message.find(c.what), std::string::npos) << message;
  }
  // Missing fields and sections.
  EXPECT_NE(ParseError(Edited(text, "  max_volts: 10.0", "  # max_volts: 10.0"))
                .find("'mems.max_volts': missing"),
            std::string::npos);
  EXPECT_NE(ParseError(Edited(text, "laser_viewport:", "laser_viewport_:"))
                .find("'laser_viewport_': unknown field"),
            std::string::npos);
  // Values that parse but fail the section's Check() name the section and the field.
  const std::string bad_gain = ParseError(Edited(text, "  lens_gain: 3.0", "  lens_gain: 0.5"));
  EXPECT_NE(bad_gain.find("section 'mems'"), std::string::npos) << bad_gain;
  EXPECT_NE(bad_gain.find("MemsLaser.lens_gain"), std::string::npos) << bad_gain;
  const std::string bad_rate =
      ParseError(Edited(text, "    sample_rate_hz: 70000.0", "    sample_rate_hz: 71000.0"));
  EXPECT_NE(bad_rate.find("section 'mems.dynamics'"), std::string::npos) << bad_rate;
  EXPECT_NE(bad_rate.find("MirrorDynamicsOptions.sample_rate_hz"), std::string::npos) << bad_rate;
  // Not YAML at all.
  EXPECT_NE(ParseError("uwscan_format: 1\nmems: [unclosed\n").find(std::string(kSource) + ":"),
            std::string::npos);
}

TEST(MemsScannerModel, ProjectionFunctionErrorsNameTheField) {
  const std::string text = TextWithFunctions();
  // f3 with a coefficient too few.
  const std::size_t f3 = text.find("  f3:");
  const std::size_t list = text.find("coefficients: [", f3);
  const std::size_t comma = text.find(", ", list);
  std::string short_list = text;
  short_list.erase(list + 15, comma + 2 - (list + 15));
  const std::string message = ParseError(short_list);
  EXPECT_NE(message.find("'projection_functions.f3.coefficients'"), std::string::npos) << message;
  EXPECT_NE(message.find("expected a list of 21 numbers"), std::string::npos) << message;
  EXPECT_NE(ParseError(Edited(text, "  f6:", "  f7:")).find("'projection_functions.f7'"),
            std::string::npos);
  const std::string degree = ParseError(Edited(text, "    degree: 5", "    degree: 12"));
  EXPECT_NE(degree.find("'projection_functions.f1.degree'"), std::string::npos) << degree;
  // A drive range without 0 V fails the section's Check().
  const std::size_t at = text.find("  volts_min: [") + 14;
  std::string no_zero = text;
  no_zero.replace(at, text.find(',', at) - at, "0.5");
  const std::string range = ParseError(no_zero);
  EXPECT_NE(range.find("section 'projection_functions'"), std::string::npos) << range;
}

}  // namespace
}  // namespace uwscan::scanner
