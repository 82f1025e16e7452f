#pragma once

#include <filesystem>

namespace uwscan::bench {

// Small valid files for every reader of bench/robustness/reader_probes.hpp: the seeds of the
// fuzzers' corpora and of `bench robustness`, written as folder/READER/seed_N.EXT. Scenes and
// scanner files are copied from data_dir; the rest is made here by uwscan's own writers (clouds,
// dive logs, databases, calibration truth, ROS bags of a simulated dive) or written out by hand
// (meshes, OpenCV YAML, reports).
void WriteReaderSeeds(const std::filesystem::path& data_dir, const std::filesystem::path& folder);

}  // namespace uwscan::bench
