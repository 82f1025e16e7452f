#pragma once

#include <cstdint>
#include <string>

namespace uwscan::bench {

// The long-dive bench's scene (issue 52): a manifold field larger than the other dives'
// racetrack, flown in laps for as long as asked. Three parallel pipelines 8 m long, 1.5 m apart,
// on a seabed at 10 m depth, each with a bolted flange, a valve and a tee with a branch in its
// own order (so no pipeline looks like another), a protection frame across their far ends,
// low mudmats across their near ends and debris beside them. The vehicle, 1 m above the
// seabed at 0.25 m/s, flies along each pipeline in turn (up the first, down the second, up the
// third), crosses back over the pipes' ends to the first, and flies the next lap the other way
// round, so each lap revisits the last one's swaths in the opposite direction. The galvanometer
// scanner and navigation drift of inspection_long.yaml, with its seed. The scanner file is
// `scanner_file`: by default relative to the data folder's scenes/ (parse the text with that base
// folder); an absolute path lets the scene be written anywhere.
// duration_s > 0; throws uwscan::Error otherwise.
std::string LongDiveSceneYaml(double duration_s, std::uint64_t seed,
                              const std::string& scanner_file = "../scanners/galvo_binned.yaml");

}  // namespace uwscan::bench
