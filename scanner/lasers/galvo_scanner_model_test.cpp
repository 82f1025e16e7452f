#include "scanner/lasers/galvo_scanner_model.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include "scanner/common/error.hpp"
#include "scanner/lasers/scanner_file.hpp"

namespace uwscan::scanner {
namespace {

// A complete, valid scanner file (the default scanner's values, shortened).
constexpr const char* kValidYaml = R"(uwscan_format: 1
camera:
  width_px: 2048
  height_px: 1088
  fx_px: 1750.0
  fy_px: 1750.0
  cx_px: 1023.5
  cy_px: 543.5
  distortion: [-0.12, 0.08, 0.0005, -0.0003, -0.02]
camera_viewport:
  normal: [0.0, 0.0, 1.0]
  distance_m: 0.03
  thickness_m: 0.012
laser:
  T_C_L:
    translation_m: [0.36, 0.0, 0.0]
    rotation_xyzw: [0.0, 1.0, 0.0, 0.0]
  T_C_M:
    translation_m: [0.30, 0.0, 0.0]
    rotation_xyzw: [0.0, 0.3214394653031616, 0.0, 0.9469301294951057]
  mirror_step_rad: 0.002
  rotation_distance_m: 0.002
  aperture_rad: 0.9599310885968813
  step_min: -100
  step_max: 100
laser_viewport:
  normal: [-0.25881904510252074, 0.0, 0.9659258262890683]
  distance_m: -0.03764571353075622
  thickness_m: 0.015
)";

constexpr const char* kSource = "test_scanner.yaml";

// 1-based number of the line of `text` that contains `needle`.
int LineOf(const std::string& text, const std::string& needle) {
  const std::size_t at = text.find(needle);
  EXPECT_NE(at, std::string::npos) << needle;
  int line = 1;
  for (std::size_t i = 0; i < at; ++i) line += text[i] == '\n' ? 1 : 0;
  return line;
}

// `kValidYaml` with the first occurrence of `from` replaced by `to`.
std::string Edited(const std::string& from, const std::string& to) {
  std::string text = kValidYaml;
  const std::size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  return text.replace(at, from.size(), to);
}

// The message of the uwscan::Error that parsing `text` throws ("" and a failure if none).
std::string ParseError(const std::string& text) {
  try {
    ParseScanner(text, kSource).galvo();
  } catch (const Error& e) {
    return e.what();
  } catch (const std::exception& e) {
    ADD_FAILURE() << "not a uwscan::Error: " << e.what();
    return e.what();
  }
  ADD_FAILURE() << "parsed without error:\n" << text;
  return "";
}

// The message names the source with a line number, and the field.
void ExpectNamesLineAndField(const std::string& message, int line, const std::string& field) {
  EXPECT_NE(message.find(std::string(kSource) + ":" + std::to_string(line) + ":"),
            std::string::npos)
      << "expected line " << line << " in: " << message;
  EXPECT_NE(message.find("'" + field + "'"), std::string::npos)
      << "expected field '" << field << "' in: " << message;
}

TEST(GalvoScannerModelTest, DefaultScannerLoadsAndChecks) {
  GalvoScannerModel model;
  ASSERT_NO_THROW(model = DefaultGalvoScannerModel());
  EXPECT_NO_THROW(model.Check());
  EXPECT_EQ(model.camera.camera.width_px, 2048);
  EXPECT_EQ(model.camera.camera.height_px, 1088);
  EXPECT_DOUBLE_EQ(model.camera.camera.fx_px, 1750.0);
  EXPECT_DOUBLE_EQ(model.camera.camera.k3, -0.02);
  EXPECT_DOUBLE_EQ(model.camera.viewport.n_glass, 1.49);
  EXPECT_DOUBLE_EQ(model.laser.viewport.thickness_m, 0.015);
  EXPECT_EQ(model.laser.step_min, -100);
  EXPECT_EQ(model.laser.step_max, 100);
  EXPECT_NEAR(model.laser.viewport.normal.norm(), 1.0, 1e-15);
}

TEST(GalvoScannerModelTest, ValidTextParsesToTheDefaultScanner) {
  const GalvoScannerModel parsed = ParseScanner(kValidYaml, kSource).galvo();
  const GalvoScannerModel expected = DefaultGalvoScannerModel();
  EXPECT_DOUBLE_EQ(parsed.camera.camera.cy_px, expected.camera.camera.cy_px);
  EXPECT_TRUE(parsed.laser.T_C_M.isApprox(expected.laser.T_C_M, 1e-15));
  EXPECT_TRUE(parsed.laser.viewport.normal.isApprox(expected.laser.viewport.normal, 1e-15));
  // Indices not given take the defaults of FlatViewport.
  EXPECT_DOUBLE_EQ(parsed.camera.viewport.n_water, FlatViewport{}.n_water);
}

TEST(GalvoScannerModelTest, MissingFieldIsNamed) {
  const std::string text = Edited("  fx_px: 1750.0\n", "");
  const std::string message = ParseError(text);
  EXPECT_NE(message.find("missing"), std::string::npos) << message;
  // A missing key has no line of its own: the message points at its section, camera:.
  ExpectNamesLineAndField(message, LineOf(text, "width_px"), "camera.fx_px");
}

TEST(GalvoScannerModelTest, NonNumericValueIsNamedWithItsLine) {
  const std::string text = Edited("fx_px: 1750.0", "fx_px: \"abc\"");
  const std::string message = ParseError(text);
  ExpectNamesLineAndField(message, LineOf(text, "fx_px"), "camera.fx_px");
  EXPECT_NE(message.find("abc"), std::string::npos) << message;
}

TEST(GalvoScannerModelTest, WrongLengthDistortionIsNamedWithItsLine) {
  const std::string text =
      Edited("[-0.12, 0.08, 0.0005, -0.0003, -0.02]", "[-0.12, 0.08, 0.0, 0.0]");
  const std::string message = ParseError(text);
  ExpectNamesLineAndField(message, LineOf(text, "distortion"), "camera.distortion");
  EXPECT_NE(message.find("5"), std::string::npos) << message;
}

TEST(GalvoScannerModelTest, UnsupportedFormatVersionIsNamedWithItsLine) {
  const std::string text = Edited("uwscan_format: 1", "uwscan_format: 2");
  const std::string message = ParseError(text);
  ExpectNamesLineAndField(message, 1, "uwscan_format");
  EXPECT_NE(message.find("2"), std::string::npos) << message;
}

TEST(GalvoScannerModelTest, NonUnitQuaternionIsNamedWithItsLine) {
  const std::string text =
      Edited("rotation_xyzw: [0.0, 1.0, 0.0, 0.0]", "rotation_xyzw: [0.0, 1.0, 0.0, 0.1]");
  const std::string message = ParseError(text);
  ExpectNamesLineAndField(message, LineOf(text, "rotation_xyzw: [0.0, 1.0, 0.0, 0.1]"),
                          "laser.T_C_L.rotation_xyzw");
}

TEST(GalvoScannerModelTest, NonUnitViewportNormalIsNamedWithItsLine) {
  const std::string text = Edited("normal: [0.0, 0.0, 1.0]", "normal: [0.0, 0.0, 1.1]");
  const std::string message = ParseError(text);
  ExpectNamesLineAndField(message, LineOf(text, "normal: [0.0, 0.0, 1.1]"),
                          "camera_viewport.normal");
  // Not the first key of its section: the line is the normal's, not the section's.
  const std::string reordered = Edited(
      "  normal: [-0.25881904510252074, 0.0, 0.9659258262890683]\n"
      "  distance_m: -0.03764571353075622\n",
      "  distance_m: -0.03764571353075622\n"
      "  normal: [-0.3, 0.0, 0.9]\n");
  ExpectNamesLineAndField(ParseError(reordered), LineOf(reordered, "normal: [-0.3"),
                          "laser_viewport.normal");
}

TEST(GalvoScannerModelTest, NonYamlGarbageNamesTheLine) {
  const std::string text = Edited("  fy_px: 1750.0\n", "  fy_px: [1750.0\n  ]]: {\n");
  const std::string message = ParseError(text);
  EXPECT_NE(message.find(kSource), std::string::npos) << message;
  EXPECT_NE(message.find("not valid YAML"), std::string::npos) << message;
  // The parser stops at or just after the broken line.
  const int broken = LineOf(text, "fy_px");
  bool names_a_nearby_line = false;
  for (int line = broken; line <= broken + 2; ++line) {
    const std::string where = std::string(kSource) + ":" + std::to_string(line) + ":";
    names_a_nearby_line = names_a_nearby_line || message.find(where) != std::string::npos;
  }
  EXPECT_TRUE(names_a_nearby_line) << message;

  const std::string binary = ParseError("\x01\x02 : : [ \t{{ \"unterminated");
  EXPECT_NE(binary.find(kSource), std::string::npos) << binary;
  EXPECT_NE(ParseError("just a sentence, not a mapping").find("top level"), std::string::npos);
}

TEST(GalvoScannerModelTest, CheckFailureNamesTheSection) {
  const std::string text = Edited("aperture_rad: 0.9599310885968813", "aperture_rad: 0.0");
  const std::string message = ParseError(text);
  EXPECT_NE(message.find(kSource), std::string::npos) << message;
  EXPECT_NE(message.find("laser"), std::string::npos) << message;
  EXPECT_NE(message.find("aperture_rad"), std::string::npos) << message;
}

TEST(GalvoScannerModelTest, LoadingAMissingFileNamesThePath) {
  const std::filesystem::path path =
      std::filesystem::temp_directory_path() / "uwscan_no_such_dir" / "no_such_scanner.yaml";
  try {
    LoadScanner(path).galvo();
    FAIL() << "loaded a missing file";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(path.string()), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace uwscan::scanner

namespace uwscan::scanner {
namespace {

TEST(ScannerModelUnknownFieldTest, MisspeltFieldIsNamedNotIgnored) {
  std::ifstream in(std::string(UWSCAN_SOURCE_DIR_FOR_TESTS) + "/data/scanners/galvo_default.yaml");
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const size_t at = text.find("  n_water: 1.33");
  ASSERT_NE(at, std::string::npos);
  text.replace(at, 15, "  nwater: 1.33");
  try {
    ParseScanner(text, "typo.yaml").galvo();
    FAIL() << "a misspelt field was accepted";
  } catch (const Error& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("camera_viewport.nwater"), std::string::npos) << message;
    EXPECT_NE(message.find("typo.yaml:"), std::string::npos) << message;
  }
}

}  // namespace
}  // namespace uwscan::scanner
