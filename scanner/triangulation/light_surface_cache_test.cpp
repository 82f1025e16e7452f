#include "scanner/triangulation/light_surface_cache.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "scanner/lasers/galvo_scanner_model.hpp"

namespace uwscan::scanner {
namespace {

namespace fs = std::filesystem;

// A short sweep keeps the cone fits quick.
GalvoLaser TestLaser() {
  GalvoLaser laser = DefaultGalvoScannerModel().laser;
  laser.step_min = -6;
  laser.step_max = 6;
  return laser;
}

fs::path Folder(const std::string& name) {
  const fs::path folder =
      fs::temp_directory_path() / ("uwscan_table_cache_" + std::to_string(::getpid()) + name);
  fs::remove_all(folder);
  return folder;
}

void ExpectSameTables(const LightSurfaceTable& a, const LightSurfaceTable& b) {
  ASSERT_EQ(a.step_min(), b.step_min());
  ASSERT_EQ(a.step_max(), b.step_max());
  EXPECT_EQ(a.has_cones(), b.has_cones());
  for (int step = a.step_min(); step <= a.step_max(); ++step) {
    const LightSurfaces& x = *a.At(step);
    const LightSurfaces& y = *b.At(step);
    EXPECT_EQ(x.plane.normal, y.plane.normal);
    EXPECT_EQ(x.plane.offset_m, y.plane.offset_m);
    EXPECT_EQ(x.cone.T_C_Q.matrix(), y.cone.T_C_Q.matrix());
    EXPECT_EQ(x.cone.a, y.cone.a);
    EXPECT_EQ(x.cone.b, y.cone.b);
    EXPECT_EQ(x.cone.beta_min_rad, y.cone.beta_min_rad);
    EXPECT_EQ(x.cone.beta_max_rad, y.cone.beta_max_rad);
    EXPECT_EQ(x.cone_rms_m, y.cone_rms_m);
    EXPECT_EQ(x.cone_converged, y.cone_converged);
  }
}

TEST(LightSurfaceCache, SecondRunReadsTheSameTableBack) {
  const fs::path folder = Folder("same");
  const GalvoLaser laser = TestLaser();
  const CachedTable first = LoadOrBuildLightSurfaceTable(laser, {}, folder);
  EXPECT_FALSE(first.from_cache);
  const CachedTable second = LoadOrBuildLightSurfaceTable(laser, {}, folder);
  EXPECT_TRUE(second.from_cache);
  ExpectSameTables(*first.table, *second.table);
  ExpectSameTables(LightSurfaceTable(laser, {}), *second.table);  // what a fresh fit gives
  fs::remove_all(folder);
}

TEST(LightSurfaceCache, AnotherCalibrationOrOptionIsNotServedTheOldTable) {
  const fs::path folder = Folder("other");
  GalvoLaser laser = TestLaser();
  LoadOrBuildLightSurfaceTable(laser, {}, folder);
  laser.viewport.distance_m += 1e-12;  // one bit-level change of the calibration
  EXPECT_FALSE(LoadOrBuildLightSurfaceTable(laser, {}, folder).from_cache);
  LightSurfaceTableOptions planes_only;
  planes_only.fit_cones = false;
  const CachedTable planes = LoadOrBuildLightSurfaceTable(laser, planes_only, folder);
  EXPECT_FALSE(planes.from_cache);
  EXPECT_FALSE(planes.table->has_cones());
  fs::remove_all(folder);
}

TEST(LightSurfaceCache, DamagedOrForeignFilesAreRebuiltNotTrusted) {
  const fs::path folder = Folder("damaged");
  const GalvoLaser laser = TestLaser();
  const CachedTable first = LoadOrBuildLightSurfaceTable(laser, {}, folder);
  ASSERT_EQ(std::distance(fs::directory_iterator(folder), fs::directory_iterator{}), 1);
  const fs::path file = fs::directory_iterator(folder)->path();
  for (const std::string& damage :
       {std::string("flip"), std::string("truncate"), std::string("foreign")}) {
    {
      std::fstream f(file, std::ios::in | std::ios::out | std::ios::binary);
      if (damage == "flip") {
        f.seekp(static_cast<std::streamoff>(fs::file_size(file) / 2));
        f.put('\x5a');
      }
    }
    if (damage == "truncate") fs::resize_file(file, fs::file_size(file) / 3);
    if (damage == "foreign") std::ofstream(file, std::ios::trunc) << "not a table";
    const CachedTable again = LoadOrBuildLightSurfaceTable(laser, {}, folder);
    EXPECT_FALSE(again.from_cache) << damage;
    ExpectSameTables(*first.table, *again.table);
    EXPECT_TRUE(LoadOrBuildLightSurfaceTable(laser, {}, folder).from_cache)
        << damage;  // rewritten whole
  }
  fs::remove_all(folder);
}

TEST(LightSurfaceCache, AnUnwritableFolderOnlyCostsTheSaving) {
  const GalvoLaser laser = TestLaser();
  const CachedTable table = LoadOrBuildLightSurfaceTable(laser, {}, "/proc/uwscan_no_such_folder");
  EXPECT_FALSE(table.from_cache);
  ExpectSameTables(LightSurfaceTable(laser, {}), *table.table);
}

}  // namespace
}  // namespace uwscan::scanner
