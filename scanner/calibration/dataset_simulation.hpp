#pragma once

#include <filesystem>
#include <functional>

#include "scanner/calibration/calibration_scene.hpp"

namespace uwscan::scanner::calibration {

// Writes the calibration dataset a calibration scene describes (calibration_scene.hpp) into
// out_folder (created; an existing folder must be empty): the images, initial_scanner.yaml (when
// the scene names one), truth.yaml (the true effective scanner and the board poses,
// calibration_dataset.hpp's DatasetTruth) and, last, manifest.yaml, so that a folder with a
// manifest is complete.
//
// Board poses are drawn from the scene's seed: the board's centre at a depth in distance_m,
// turned by up to max_tilt_rad from facing the camera and by up to max_roll_rad about its
// normal, kept only when every corner of the pattern lies in the image (with a margin) and its
// squares are large enough to be found; for the laser steps, also when every mirror step's
// stripe falls on the board, and for mems when at least a quarter of the voltage grid's dots
// do. Then per pose:
//   intrinsics, viewport: view_NNN.png, the pattern (TargetRenderer).
//   laser, laser_viewport: plane_PP.png, the pattern with the laser off; plane_PP_step_mSSS.png
//     (pSSS for positive steps) per mirror step, the stripe on the board with the lights off,
//     rendered by the simulator (sim::Simulator, the board a plane object of
//     board_reflectance) with the scene's image effects (the `image` stage is switched on when
//     the scene has none).
//   mems: plane_PP.png; plane_PP_dot_KKK.png per voltage pair k of the grid (row by row, x
//     fastest) whose dot lands on the board and in the image (the others are left out): a
//     Gaussian dot at the exact projection of the true beam's hit on the board, sized by the
//     beam's footprint (effects.beam, or its defaults) and the blur (effects.image), as bright as
//     the simulator's stripes, over the ambient level, with read noise when sensor_noise is on.
// Images are 8- or 16-bit greyscale PNG as effects.image.format says. Same scene and seed, same
// dataset, whatever the thread count. `progress` (optional) gets the fraction of images
// written, 0 to 1, one call at a time but possibly from OpenMP worker threads.
//
// Throws uwscan::Error when the scene fails CalibrationScene::Check, when out_folder exists
// and is not an empty folder, when no board pose
// meets the conditions above within a few thousand draws (the message says what to change), or
// on I/O errors (naming the file).
void SimulateCalibrationDataset(const CalibrationScene& scene,
                                const std::filesystem::path& out_folder,
                                const std::function<void(double)>& progress = {});

// LoadCalibrationScene(calibration_scene), then the above.
void SimulateCalibrationDataset(const std::filesystem::path& calibration_scene,
                                const std::filesystem::path& out_folder,
                                const std::function<void(double)>& progress = {});

}  // namespace uwscan::scanner::calibration
