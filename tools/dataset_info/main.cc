// dataset_info: what a dataset folder holds, as the other tools will see it.
#include <cstdio>

#include "app/tool.h"
#include "core/progress.h"
#include "io/dataset.h"

int main(int argc, char** argv) {
  jvl::app::Tool tool("dataset_info",
                      "Print the frames, calibration and ground truth of a dataset folder "
                      "(KITTI odometry sequence, KITTI raw drive or synthetic sequence).");
  std::string dataset, format = "auto", frames;
  bool check_scans = false;
  tool.cli().add_option("-d,--dataset", dataset, "Dataset folder")->required();
  tool.cli().add_option("--format", format, "auto, kitti or kitti-raw")->capture_default_str();
  tool.cli().add_option("--frames", frames, "Frame range A:B (B exclusive)");
  tool.cli().add_flag("--check-scans", check_scans, "Read every scan and report point counts");
  return tool.Run(argc, argv, [&] {
    const auto ds = jvl::io::OpenDataset(dataset, jvl::io::ParseDatasetFormat(format),
                                         jvl::ParseFrameRange(frames));
    const auto& c = ds->calibration();
    const auto cam = c.Camera(0);
    std::printf("dataset      %s\nid           %s\n", ds->root().c_str(), ds->id().c_str());
    std::printf("frames       %zu (%lld..%lld), %.2f s\n", ds->frames().size(),
                static_cast<long long>(ds->frames().front()),
                static_cast<long long>(ds->frames().back()),
                ds->timestamps().back() - ds->timestamps().front());
    std::printf("camera 0     fx %.4f fy %.4f cx %.4f cy %.4f, %dx%d\n", cam.fx, cam.fy, cam.cx,
                cam.cy, c.image_width, c.image_height);
    const auto t = c.cam0_from_velo.translation();
    std::printf("cam0<-velo   t = (%.4f, %.4f, %.4f) m\n", t.x(), t.y(), t.z());
    if (ds->ground_truth()) {
      const auto& gt = *ds->ground_truth();
      double length = 0;
      for (size_t i = 1; i < gt.size(); ++i)
        length +=
            (gt.world_from_cam[i].translation() - gt.world_from_cam[i - 1].translation()).norm();
      std::printf("ground truth %zu poses, path length %.2f m\n", gt.size(), length);
    } else {
      std::printf("ground truth none\n");
    }
    if (check_scans) {
      size_t total = 0, dropped_total = 0;
      jvl::Progress progress("scans", static_cast<int64_t>(ds->frames().size()), !tool.quiet());
      for (int64_t f : ds->frames()) {
        size_t dropped = 0;
        total += ds->LoadScan(f, &dropped).size();
        dropped_total += dropped;
        progress.Tick();
      }
      std::printf("scans        %.0f points per scan on average, %zu non-finite dropped\n",
                  static_cast<double>(total) / ds->frames().size(), dropped_total);
    }
  });
}
