#include "io/h5_probe.h"

#include <fcntl.h>
#include <hdf5.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <csignal>
#include <string>

#if defined(__SANITIZE_ADDRESS__)
#define JVL_H5_PROBE_SANITIZED 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(undefined_behavior_sanitizer)
#define JVL_H5_PROBE_SANITIZED 1
#endif
#endif
#if JVL_H5_PROBE_SANITIZED
#include <sanitizer/common_interface_defs.h>
#endif

namespace jvl::io {
namespace {

#if H5_VERSION_GE(1, 12, 0)
using ObjectInfo = H5O_info2_t;
#define JVL_H5_PROBE_VISIT(file, op, data) \
  H5Ovisit3(file, H5_INDEX_NAME, H5_ITER_INC, op, data, H5O_INFO_BASIC)
#else
using ObjectInfo = H5O_info_t;
#define JVL_H5_PROBE_VISIT(file, op, data) H5Ovisit(file, H5_INDEX_NAME, H5_ITER_INC, op, data)
#endif

// Reads what H5Reader reads of an attribute: type, shape and, for a small scalar string, value.
herr_t ProbeAttribute(hid_t object, const char* name, const H5A_info_t*, void*) {
  const hid_t attr = H5Aopen(object, name, H5P_DEFAULT);
  if (attr < 0) return 0;
  const hid_t type = H5Aget_type(attr);
  const hid_t space = H5Aget_space(attr);
  if (type >= 0 && space >= 0 && H5Sget_simple_extent_npoints(space) == 1 &&
      H5Tget_class(type) == H5T_STRING && H5Tis_variable_str(type) == 0) {
    const size_t size = H5Tget_size(type);
    if (size > 0 && size <= (size_t{1} << 28)) {
      std::string value(size, '\0');
      H5Aread(attr, type, value.data());
    }
  }
  if (space >= 0) H5Sclose(space);
  if (type >= 0) H5Tclose(type);
  H5Aclose(attr);
  return 0;
}

herr_t ProbeObject(hid_t file, const char* name, const ObjectInfo* info, void*) {
  const hid_t object = H5Oopen(file, name, H5P_DEFAULT);
  if (object < 0) return 0;
  hsize_t index = 0;
  H5Aiterate2(object, H5_INDEX_NAME, H5_ITER_INC, &index, ProbeAttribute, nullptr);
  if (info->type == H5O_TYPE_DATASET) {
    const hid_t type = H5Dget_type(object);
    const hid_t space = H5Dget_space(object);
    if (space >= 0) {
      hsize_t dims[H5S_MAX_RANK];
      H5Sget_simple_extent_dims(space, dims, nullptr);
      H5Sclose(space);
    }
    if (type >= 0) H5Tclose(type);
  }
  H5Oclose(object);
  return 0;
}

}  // namespace

bool Hdf5MetadataWalkSurvives(const std::string& path) {
  const pid_t pid = ::fork();
  if (pid < 0) return true;  // No child: read without the probe.
  if (pid == 0) {
    // The child only walks the file; a crash report of its own (sanitizer builds) is noise,
    // and so are crash handlers inherited from the parent (a libFuzzer parent's would write a
    // crash-* file for every damaged input the probe catches): die with the default action.
    const int null = ::open("/dev/null", O_WRONLY);
    if (null >= 0) ::dup2(null, STDERR_FILENO);
    for (const int sig : {SIGSEGV, SIGBUS, SIGABRT, SIGFPE, SIGILL}) std::signal(sig, SIG_DFL);
#if JVL_H5_PROBE_SANITIZED
    __sanitizer_set_death_callback(nullptr);  // libFuzzer's writes a crash-* file on a report
#endif
    H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
    const hid_t file = H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
    if (file >= 0) {
      hsize_t index = 0;
      H5Aiterate2(file, H5_INDEX_NAME, H5_ITER_INC, &index, ProbeAttribute, nullptr);
      JVL_H5_PROBE_VISIT(file, ProbeObject, nullptr);
      H5Fclose(file);
    }
    ::_exit(0);
  }
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0) {
    if (errno != EINTR) return true;  // The child cannot be waited for: no verdict.
  }
  return WIFEXITED(status) && WEXITSTATUS(status) == 0;
}

}  // namespace jvl::io
