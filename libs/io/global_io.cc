#include "io/global_io.h"

#include "core/check.h"
#include "io/trajectory_io.h"

namespace jvl::io {

void WriteGlobalArtifact(const std::string& path, const GlobalData& data,
                         const Provenance& provenance) {
  data.keyframes.Check("global keyframes");
  data.trajectory.Check("global trajectory");
  data.prior.Check("global prior");
  H5Writer w(path, kGlobalSchema, kGlobalSchemaVersion);
  WriteTrajectoryGroup(w, "keyframes", data.keyframes);
  WriteTrajectoryGroup(w, "trajectory", data.trajectory);
  WriteTrajectoryGroup(w, "prior", data.prior);
  w.WriteJson("stats", data.stats);
  w.Commit(provenance);
}

GlobalData ReadGlobalArtifact(const std::string& path) {
  const H5Reader r(path, kGlobalSchema, kGlobalSchemaVersion);
  GlobalData d;
  d.keyframes = ReadTrajectoryGroup(r, "keyframes");
  d.trajectory = ReadTrajectoryGroup(r, "trajectory");
  d.prior = ReadTrajectoryGroup(r, "prior");
  d.stats = r.ReadJson("stats");
  for (const int64_t f : d.keyframes.frames)
    JVL_CHECK(d.trajectory.IndexOf(f).has_value(),
              path << ": keyframe " << f << " is not a frame of trajectory/");
  return d;
}

}  // namespace jvl::io
