// libhdf5 1.10 reads some damaged files into a crash (a null or wild pointer in its object
// header code) instead of returning an error; fuzzing the artifact readers found several. Before
// H5Reader trusts the library with a file, a child process opens it and walks every object,
// attribute and dataset header the readers touch: if the child dies, the file is reported as
// damaged and the tool never reaches the crash.
#pragma once

#include <string>

namespace jvl::io {

// True if walking the metadata of the HDF5 file at `path` completes (or fails with an HDF5
// error, which the caller reports); false if the walk crashed.
bool Hdf5MetadataWalkSurvives(const std::string& path);

}  // namespace jvl::io
