// libFuzzer target: HDF5 artifact readers. The input is written to a temporary file, opened with
// H5Reader, read with the reader of the schema it names, and checked against that schema file.
// A damaged file must raise jvl::Error, nothing else.
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>

#include "core/check.h"
#include "io/artifact.h"
#include "io/directions_io.h"
#include "io/global_io.h"
#include "io/local_io.h"
#include "io/odometry_io.h"
#include "io/schema_check.h"
#include "io/trajectory_io.h"
#include "io/visual_io.h"
#include "io/vps_io.h"

namespace {

// The temporary file of this process (under $TMPDIR, else /tmp), removed when the fuzzer exits:
// every run used to leave one behind.
class TempInput {
 public:
  TempInput() {
    const char* dir = std::getenv("TMPDIR");
    path_ = std::string(dir && *dir ? dir : "/tmp") + "/jvl_artifact_fuzz_" +
            std::to_string(::getpid()) + ".h5";
  }
  ~TempInput() { std::remove(path_.c_str()); }
  const std::string& path() const { return path_; }

 private:
  std::string path_;
};

const std::string& InputPath() {
  static const TempInput input;
  return input.path();
}

void ReadAs(const std::string& schema, const std::string& path) {
  using namespace jvl::io;
  if (schema == "trajectory") ReadTrajectory(path, TrajectoryFormat::kH5);
  if (schema == "odometry") ReadOdometryArtifact(path);
  if (schema == "vps") ReadVpsArtifact(path);
  if (schema == "directions") ReadDirectionsArtifact(path);
  if (schema == "visual") ReadVisualMap(path);
  if (schema == "local") {
    ReadLocalMap(path);
    ReadLocalScans(path, [](size_t, const float*, const float*, size_t) {});
  }
  if (schema == "global") ReadGlobalArtifact(path);
}

}  // namespace

// libhdf5 trusts sizes read from the file and may ask for tens of gigabytes; let such requests
// fail (HDF5 then reports an error), as a plain malloc of more than the machine has does,
// instead of stopping the fuzzer. No allocation of a valid small artifact comes near 512 MB.
// libhdf5 also leaks on some error paths (not our code: the unit tests check ours). Every
// H5Reader forks its metadata probe (io/h5_probe.h); a small quarantine keeps the process, and
// so each fork's page-table copy, small.
extern "C" const char* __asan_default_options() {
  return "allocator_may_return_null=1:max_allocation_size_mb=512:detect_leaks=0:"
         "quarantine_size_mb=16";
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string& path = InputPath();
  {
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  }
  std::string schema;
  try {
    jvl::io::H5Reader reader(path, "", 0);
    schema = reader.schema();
    reader.ListDatasets();
    reader.ListAttributes();
    reader.provenance();
  } catch (const jvl::Error&) {
    return 0;
  }
  for (const char* known :
       {"trajectory", "odometry", "vps", "directions", "visual", "local", "global"}) {
    if (schema != known) continue;
    try {
      ReadAs(schema, path);
    } catch (const jvl::Error&) {
      continue;  // The schema check below would stop at the same damage.
    } catch (const std::bad_alloc&) {
      // Shapes up to ~1000x the file size pass the reader's check and may still not fit in the
      // fuzzer's 512 MB allocation limit; a tool reports these as "out of memory".
      continue;
    }
    try {
      jvl::io::CheckH5AgainstSchema(
          path, std::string(JVL_SOURCE_DIR) + "/schemas/" + schema + ".schema.json");
    } catch (const jvl::Error&) {
    }
  }
  return 0;
}
