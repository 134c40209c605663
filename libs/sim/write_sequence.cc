#include "sim/write_sequence.h"

#include <atomic>

#include "core/timer.h"
#include "io/kitti.h"
#include "io/sim_io.h"
#include "sim/describe.h"

namespace jvl::sim {

WriteStats WriteSequence(const World& world, const io::SequenceLayout& layout_in, int threads,
                         const std::function<io::Provenance()>& provenance,
                         const std::function<void()>& tick) {
  const SequenceOptions& opt = world.options;
  io::SequenceLayout layout = layout_in;
  layout.times = world.ground_truth.timestamps;
  // The calibration as written (with the calibration error, if any); the data come from the rig.
  io::WriteSequenceMetadata(layout, WrittenCalibration(opt), world.ground_truth);
  std::vector<std::vector<io::GtVpRow>> vps(world.ground_truth.size());
  std::atomic<int64_t> points{0};
  Timer timer;
  GenerateSequence(world, threads, [&](SimFrame&& f) {
    if (opt.simulate_scans) io::WriteSequenceScan(layout, f.frame, f.scan);
    if (opt.render_images && !f.image.empty()) io::WriteImage(layout.ImagePath(f.frame), f.image);
    for (const auto& [camera, image] : f.other_images)
      io::WriteImage(layout.ImagePath(f.frame, camera), image);
    points += static_cast<int64_t>(f.scan.size());
    const size_t slot = *world.ground_truth.IndexOf(f.frame);
    for (const GtVanishingPoint& v : f.vps) {
      vps[slot].push_back(
          {f.frame, ToString(v.kind), v.group, v.direction_cam, v.uv, v.in_image, v.buildings});
    }
    if (tick) tick();
  });
  WriteStats stats;
  stats.frame_seconds = timer.ElapsedSeconds();
  stats.frames = static_cast<int64_t>(vps.size());
  stats.points = points.load();
  const io::Provenance prov = provenance();
  std::vector<io::GtVpRow> rows;
  for (const auto& v : vps) rows.insert(rows.end(), v.begin(), v.end());
  io::WriteGtVpsCsv(layout.SimDir() + "/gt_vps.csv", rows);
  io::WriteGtVpsJson(layout.SimDir() + "/gt_vps.json", opt.calibration.Camera(0),
                     world.ground_truth.frames, rows, prov);
  io::WriteSceneJson(layout.SimDir() + "/scene.json", DescribeScene(world), prov);
  return stats;
}

}  // namespace jvl::sim
