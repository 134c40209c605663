// Checks an artifact against its file in schemas/: the HDF5 layout ("x-hdf5": datasets with
// dtype and symbolic shape, root attributes) and JSON documents (a subset of JSON Schema:
// type, required, properties, additionalProperties, items, enum, minimum, maximum, $ref to a
// sibling schema file or "#/$defs/...").
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace jvl::io {

// Problems found (empty = valid). schema_path is the schema file.
std::vector<std::string> CheckH5AgainstSchema(const std::string& h5_path,
                                              const std::string& schema_path);
std::vector<std::string> CheckJsonAgainstSchema(const nlohmann::json& doc,
                                                const std::string& schema_path);

}  // namespace jvl::io
