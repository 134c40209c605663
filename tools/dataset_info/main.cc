// dataset_info: what a dataset folder holds, as the other tools will see it.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include "app/tool.h"
#include "core/check.h"
#include "core/progress.h"
#include "core/timer.h"
#include "io/dataset.h"
#include "io/trajectory_io.h"

int main(int argc, char** argv) {
  jvl::app::Tool tool(
      "dataset_info",
      "Print the frames, calibration and ground truth of a dataset folder "
      "(KITTI odometry sequence, KITTI raw drive, KITTI-360 drive, Oxford RobotCar traversal or "
      "synthetic sequence).");
  std::string dataset, frames, write_gt;
  jvl::io::DatasetOptions dataset_options;
  bool check_scans = false, check_images = false;
  int camera = 0;
  tool.cli().add_option("-d,--dataset", dataset, "Dataset folder")->required();
  tool.AddDatasetOptions(&dataset_options);
  tool.cli().add_option("--frames", frames, "Frame range A:B (B exclusive)");
  tool.cli().add_flag("--check-scans", check_scans,
                      "Read every scan and report point counts and reading speed");
  tool.cli().add_flag("--check-images", check_images,
                      "Read every image of --camera and report the reading speed");
  tool.cli().add_option("--camera", camera, jvl::io::kCameraHelp)->capture_default_str();
  tool.OutputFile(
      tool.cli().add_option("--write-gt", write_gt,
                            "Write the ground truth of the selected frames as the tools see it "
                            "(world_from_cam0, KITTI text with frame numbers: what evaluate --gt "
                            "takes, e.g. for KITTI-360, whose poses skip frames)"));
  return tool.Run(argc, argv, [&] {
    const auto ds = jvl::io::OpenDataset(dataset, dataset_options, jvl::ParseFrameRange(frames));
    tool.AddDataset(*ds, dataset);  // Refuses a --write-gt that is one of the dataset's files.
    const auto& c = ds->calibration();
    const auto cam = c.Camera(0);
    std::printf("dataset      %s\nformat       %s\nid           %s\n", ds->root().c_str(),
                jvl::io::DatasetFormatName(ds->format()), ds->id().c_str());
    std::printf("frames       %zu (%lld..%lld), %.2f s\n", ds->frames().size(),
                static_cast<long long>(ds->frames().front()),
                static_cast<long long>(ds->frames().back()),
                ds->timestamps().back() - ds->timestamps().front());
    std::printf("camera 0     fx %.4f fy %.4f cx %.4f cy %.4f, %dx%d\n", cam.fx, cam.fy, cam.cx,
                cam.cy, c.image_width, c.image_height);
    const auto t = c.cam0_from_velo.translation();
    std::printf("cam0<-velo   t = (%.4f, %.4f, %.4f) m\n", t.x(), t.y(), t.z());
    if (!ds->calibration_file().empty())
      std::printf("calibration  %s (--calib, in place of the dataset's)\n",
                  ds->calibration_file().c_str());
    if (ds->ground_truth()) {
      const auto& gt = *ds->ground_truth();
      double length = 0;
      for (size_t i = 1; i < gt.size(); ++i)
        length +=
            (gt.world_from_cam[i].translation() - gt.world_from_cam[i - 1].translation()).norm();
      std::printf("ground truth %zu poses, path length %.2f m\n", gt.size(), length);
      if (!write_gt.empty()) {
        jvl::io::WriteTrajectoryKitti(write_gt, gt, /*force_index=*/true);
        std::printf("wrote        %s\n", write_gt.c_str());
      }
    } else {
      std::printf("ground truth none\n");
      JVL_CHECK(write_gt.empty(), "--write-gt: " << dataset << " has no ground truth");
    }
    if (!ds->scan_time_offsets().empty()) {
      // Oxford: each scan is the sweep nearest its image, taken up to half a sweep before or
      // after it (compensated where the tools de-skew: lidar_odom, local_map).
      std::vector<double> ms;
      for (const double o : ds->scan_time_offsets()) ms.push_back(1e3 * o);
      std::vector<double> magnitude;
      for (const double o : ms) magnitude.push_back(std::abs(o));
      std::sort(magnitude.begin(), magnitude.end());
      double sum = 0;
      for (const double o : ms) sum += o;
      std::printf(
          "scan time    sweep minus image time: mean %+.1f ms, min %+.1f ms, max %+.1f ms, "
          "|offset| median %.1f ms\n",
          sum / static_cast<double>(ms.size()), *std::min_element(ms.begin(), ms.end()),
          *std::max_element(ms.begin(), ms.end()), magnitude[magnitude.size() / 2]);
    }
    if (check_scans) {
      size_t total = 0, dropped_total = 0;
      jvl::Progress progress("scans", static_cast<int64_t>(ds->frames().size()), !tool.quiet());
      jvl::Timer timer;
      for (int64_t f : ds->frames()) {
        size_t dropped = 0;
        total += ds->LoadScan(f, &dropped).size();
        dropped_total += dropped;
        progress.Tick();
      }
      const double seconds = timer.ElapsedSeconds();
      std::printf(
          "scans        %.0f points per scan on average, %zu non-finite dropped; read at %.1f "
          "scans/s\n",
          static_cast<double>(total) / ds->frames().size(), dropped_total,
          ds->frames().size() / std::max(seconds, 1e-9));
    }
    if (check_images) {
      ds->CheckCamera(camera);
      jvl::Progress progress("images", static_cast<int64_t>(ds->frames().size()), !tool.quiet());
      jvl::Timer timer;
      for (int64_t f : ds->frames()) {
        ds->LoadImage(f, camera);
        progress.Tick();
      }
      std::printf("images       read at %.1f images/s\n",
                  ds->frames().size() / std::max(timer.ElapsedSeconds(), 1e-9));
    }
  });
}
