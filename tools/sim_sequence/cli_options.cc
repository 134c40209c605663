#include "cli_options.h"

#include <map>
#include <string>

#include "app/option_group.h"

namespace jvl::tools {

void AddSimSequenceFlags(app::Tool& tool, sim::SequenceOptions* o) {
  app::OptionGroup route(tool, "Route");
  route.Add("--laps", "laps", o->laps,
            "Drive the route this many times, every second lap mirrored (long sequences); "
            "with --scenario loop: circuits of the block; with figure8: figure eights");
  route.Add("--seed", o->seed, "Random seed (world layout and noise)");
  route.Add("--road-beyond", "road_beyond", o->road_beyond,
            "The road and the world along it continue this far (m) straight beyond both ends "
            "of the drive (default: the LiDAR's maximum range); 0: the world ends where the "
            "drive does");
  route.Flag("--stop", o->stop, "Stop for a few seconds before the second corner");
  route.Add("--steer-transition", o->drive.steer_transition,
            "Arc length (m) over which the vehicle's curvature, yaw rate and body roll ramp into "
            "and out of a turn (0: they step where the road does)");
  route.Add("--body-vibration", "body_vibration", o->drive.body_vibration,
            "RMS (deg) of the body's pitch and roll vibration while moving (0: the body follows "
            "the terrain)");

  app::OptionGroup sensors(tool, "Sensors");
  sensors.Add("--range-noise", o->lidar.range_noise, "LiDAR range noise sigma (m)");
  sensors.Add("--dropout", "dropout", o->lidar.dropout, "LiDAR random dropout probability");
  sensors.Flag("--motion-distortion", o->lidar.motion_distortion,
               "Move the LiDAR during the 0.1 s sweep");
  sensors.Add("--lidar-elevation-bias", "elevation_bias_deg", o->lidar.elevation_bias_deg,
              "Report every LiDAR return this much (deg) below its beam, as the KITTI HDL-64E "
              "scans do (the default gives calib_check KITTI 04's pitch reading; lidar_odom "
              "--vertical-correction undoes it); 0: none");
  static const std::map<std::string, sim::BeamTable> kBeamTables{
      {"nominal", sim::BeamTable::kNominal}, {"kitti04", sim::BeamTable::kKitti04}};
  sensors
      .Add("--lidar-beams", "beam_table", o->lidar.beam_table,
           "LiDAR beam elevations: nominal (the HDL-64E's two evenly spaced blocks, +2 to -24.9 "
           "deg) or kitti04 (each ring at the median elevation of the real KITTI 04 scans' ring, "
           "+2.37 to -23.70 deg as reported at the default --lidar-elevation-bias)")
      ->transform(CLI::CheckedTransformer(kBeamTables, CLI::ignore_case).description(""))
      ->type_name("{nominal,kitti04}")
      ->default_str("nominal");
  sensors.Add("--calib-error-deg", "calib_error_deg", o->calib_error_deg,
              "Write calib.txt's camera-LiDAR extrinsic (Tr) rotated this much (deg) off the "
              "rig the data come from, about an axis drawn from the seed; 0: the true rig");
  sensors.Add("--calib-error-m", "calib_error_m", o->calib_error_m,
              "... and moved this far (m) along a direction drawn from the seed");
  sensors.Add("--pixel-noise", o->camera.pixel_noise, "Image noise sigma (grey levels)");
  sensors
      .Add("--supersample", o->camera.supersample,
           "Camera rays per pixel along each axis, on a rotated grid, where the pixel "
           "sees an edge (its area is averaged); 1: one ray per pixel centre")
      ->check(CLI::Range(1, 8));
  sensors.Add("--supersample-contrast", o->camera.supersample_contrast,
              "A pixel is supersampled where its neighbourhood sees another surface or the "
              "second difference of neighbouring centre rays exceeds this many grey levels "
              "(negative: every pixel)");
  sensors.Add("--exposure-variation", o->camera.exposure_variation,
              "Relative frame-to-frame exposure change");

  app::OptionGroup world(tool, "World");
  world.Add("--moving-cars", o->scene.moving_cars, "Moving cars on the route");
  world.Add("--terrain-scale", o->scene.terrain_scale,
            "Scale of the rolling terrain's heights and slopes (0 = flat, 1 = slopes of a "
            "few percent)");
  world.Add("--foliage-density", "foliage_density", o->scene.foliage_density,
            "Leaf area density of tree crowns and bushes (m^2/m^3): volumes of leaf clumps "
            "that LiDAR and camera rays pass through (0 = one opaque surface each)");
  world.Add("--hedges", "hedge_coverage", o->scene.hedge_coverage,
            "Fraction of each roadside lined by hedge rows beyond the sidewalk (default: 0.7 "
            "on highway and straight, 0 elsewhere)");
}

}  // namespace jvl::tools
