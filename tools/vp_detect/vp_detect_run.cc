#include "vp_detect_run.h"

#include <cstdio>

#include "core/check.h"
#include "core/progress.h"
#include "core/threads.h"
#include "core/timer.h"
#include "io/files.h"
#include "io/kitti.h"
#include "vision/vp_overlay.h"

namespace jvl {

std::vector<io::VpRecord> ToRecords(int64_t frame, const VpResult& result) {
  std::vector<io::VpRecord> rows;
  for (size_t k = 0; k < result.vps.size(); ++k) {
    const VanishingPoint& vp = result.vps[k];
    io::VpRecord r;
    r.frame = frame;
    r.index = static_cast<int32_t>(k);
    r.uv = vp.uv;
    r.direction = vp.direction;
    r.inliers = vp.inliers;
    r.residual_deg = vp.residual_deg;
    r.score = vp.score;
    r.is_forward = vp.is_forward;
    rows.push_back(r);
  }
  return rows;
}

VpDetectRunResult RunVpDetect(const io::Dataset& dataset, const VpDetectRunOptions& options) {
  options.detect.Check();
  const std::vector<int64_t>& frames = dataset.frames();
  VpDetectRunResult out;
  out.data.frames = frames;
  dataset.CheckCamera(options.camera);
  out.data.camera = dataset.calibration().Camera(options.camera);
  out.data.camera_choice = CameraChoice::Of(dataset.calibration(), options.camera);
  if (frames.empty()) return out;
  if (out.data.camera.width <= 0) {
    const cv::Mat first = dataset.LoadImage(frames.front(), options.camera);
    out.data.camera.width = first.cols;
    out.data.camera.height = first.rows;
  }
  out.data.camera.Check();
  if (!options.debug_dir.empty()) io::CreateDirectories(options.debug_dir);

  const int64_t n = static_cast<int64_t>(frames.size());
  std::vector<std::vector<io::VpRecord>> per_frame(frames.size());
  out.detect_ms.assign(frames.size(), 0.0);
  Progress progress("vp_detect", n, options.progress);
  ParallelFor(n, options.threads, [&](int64_t i) {
    const int64_t frame = frames[i];
    const cv::Mat image = dataset.LoadImage(frame, options.camera);
    JVL_CHECK(image.cols == out.data.camera.width && image.rows == out.data.camera.height,
              dataset.ImagePath(frame, options.camera)
                  << ": image is " << image.cols << "x" << image.rows << ", expected "
                  << out.data.camera.width << "x" << out.data.camera.height);
    Timer timer;
    const VpResult result = DetectVanishingPoints(image, out.data.camera, options.detect);
    out.detect_ms[i] = 1e3 * timer.ElapsedSeconds();
    per_frame[i] = ToRecords(frame, result);
    if (!options.debug_dir.empty()) {
      char name[32];
      std::snprintf(name, sizeof(name), "/%06lld.png", static_cast<long long>(frame));
      io::WriteImage(options.debug_dir + name, DrawVpOverlay(image, out.data.camera, result));
    }
    progress.Tick();
  });
  for (const auto& rows : per_frame) {
    out.data.vps.insert(out.data.vps.end(), rows.begin(), rows.end());
    out.frames_with_vps += rows.empty() ? 0 : 1;
    for (const io::VpRecord& r : rows) out.frames_with_forward += r.is_forward ? 1 : 0;
  }
  return out;
}

}  // namespace jvl
