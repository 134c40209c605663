#include "io/schema_check.h"

#include <filesystem>
#include <map>

#include "core/check.h"
#include "io/artifact.h"
#include "io/files.h"

namespace jvl::io {
namespace {

nlohmann::json LoadSchema(const std::string& path) {
  try {
    return nlohmann::json::parse(ReadTextFile(path));
  } catch (const nlohmann::json::exception& e) {
    JVL_THROW(path << ": schema is not valid JSON: " << JsonErrorText(e));
  }
}

class JsonValidator {
 public:
  JsonValidator(nlohmann::json root, std::string dir) : root_(std::move(root)), dir_(std::move(dir)) {}

  void Validate(const nlohmann::json& doc, const nlohmann::json& schema, const std::string& where) {
    if (schema.contains("$ref")) {
      const std::string ref = schema["$ref"];
      if (ref.rfind("#/$defs/", 0) == 0) {
        Validate(doc, root_["$defs"][ref.substr(8)], where);
      } else {
        JsonValidator other(LoadSchema(dir_ + "/" + ref), dir_);
        other.Validate(doc, other.root_, where);
      }
      return;
    }
    if (schema.contains("type") && !TypeMatches(doc, schema["type"])) {
      problems.push_back(where + ": expected type " + schema["type"].dump() + ", found " +
                         std::string(doc.type_name()));
      return;
    }
    if (schema.contains("enum")) {
      bool found = false;
      for (const auto& v : schema["enum"]) found |= v == doc;
      if (!found) problems.push_back(where + ": value " + doc.dump() + " not in enum");
    }
    if (doc.is_number()) {
      if (schema.contains("minimum") && doc.get<double>() < schema["minimum"].get<double>())
        problems.push_back(where + ": below minimum");
      if (schema.contains("maximum") && doc.get<double>() > schema["maximum"].get<double>())
        problems.push_back(where + ": above maximum");
    }
    if (doc.is_object()) {
      for (const auto& r : schema.value("required", nlohmann::json::array())) {
        if (!doc.contains(r.get<std::string>()))
          problems.push_back(where + ": missing required member '" + r.get<std::string>() + "'");
      }
      const auto props = schema.value("properties", nlohmann::json::object());
      for (auto it = doc.begin(); it != doc.end(); ++it) {
        if (props.contains(it.key())) {
          Validate(it.value(), props[it.key()], where + "." + it.key());
        } else if (schema.contains("additionalProperties")) {
          const auto& ap = schema["additionalProperties"];
          if (ap.is_boolean() && !ap.get<bool>())
            problems.push_back(where + ": unexpected member '" + it.key() + "'");
          else if (ap.is_object())
            Validate(it.value(), ap, where + "." + it.key());
        }
      }
    }
    if (doc.is_array() && schema.contains("items")) {
      for (size_t i = 0; i < doc.size(); ++i)
        Validate(doc[i], schema["items"], where + "[" + std::to_string(i) + "]");
    }
  }

  std::vector<std::string> problems;

 private:
  static bool TypeMatches(const nlohmann::json& doc, const nlohmann::json& type) {
    if (type.is_array()) {
      for (const auto& t : type)
        if (TypeMatches(doc, t)) return true;
      return false;
    }
    const std::string t = type;
    if (t == "object") return doc.is_object();
    if (t == "array") return doc.is_array();
    if (t == "string") return doc.is_string();
    if (t == "integer") return doc.is_number_integer();
    if (t == "number") return doc.is_number();
    if (t == "boolean") return doc.is_boolean();
    if (t == "null") return doc.is_null();
    return false;
  }

  nlohmann::json root_;
  std::string dir_;
};

std::string Dir(const std::string& path) {
  return std::filesystem::path(path).parent_path().string();
}

}  // namespace

std::vector<std::string> CheckJsonAgainstSchema(const nlohmann::json& doc,
                                                const std::string& schema_path) {
  JsonValidator v(LoadSchema(schema_path), Dir(schema_path));
  v.Validate(doc, LoadSchema(schema_path), "$");
  return v.problems;
}

std::vector<std::string> CheckH5AgainstSchema(const std::string& h5_path,
                                              const std::string& schema_path) {
  const nlohmann::json schema = LoadSchema(schema_path);
  JVL_CHECK(schema.contains("x-hdf5"), schema_path << ": no x-hdf5 layout");
  const auto& layout = schema["x-hdf5"];
  std::vector<std::string> problems;
  H5Reader reader(h5_path, layout["schema"].get<std::string>(),
                  layout["schema_version"].get<int>());
  // Symbolic dimensions ("N") must agree across datasets.
  std::map<std::string, int64_t> sizes;
  for (auto it = layout["datasets"].begin(); it != layout["datasets"].end(); ++it) {
    const std::string& name = it.key();
    const auto& spec = it.value();
    if (!reader.Has(name)) {
      if (spec.value("required", true)) problems.push_back(name + ": missing dataset");
      continue;
    }
    const std::string dtype = reader.DatasetType(name);
    if (dtype != spec["dtype"].get<std::string>())
      problems.push_back(name + ": dtype " + dtype + ", schema says " + spec["dtype"].dump());
    const auto dims = reader.Dims(name);
    const auto& shape = spec["shape"];
    if (dims.size() != shape.size()) {
      problems.push_back(name + ": rank " + std::to_string(dims.size()) + ", schema says " +
                         std::to_string(shape.size()));
      continue;
    }
    for (size_t i = 0; i < dims.size(); ++i) {
      if (shape[i].is_number_integer()) {
        if (dims[i] != shape[i].get<int64_t>())
          problems.push_back(name + ": dimension " + std::to_string(i) + " is " +
                             std::to_string(dims[i]) + ", schema says " + shape[i].dump());
      } else {
        const std::string sym = shape[i];
        const auto [pos, inserted] = sizes.emplace(sym, dims[i]);
        if (!inserted && pos->second != dims[i])
          problems.push_back(name + ": dimension " + sym + " is " + std::to_string(dims[i]) +
                             " here but " + std::to_string(pos->second) + " elsewhere");
      }
    }
  }
  // Every dataset in the file is documented.
  for (const auto& name : reader.ListDatasets()) {
    if (!layout["datasets"].contains(name)) problems.push_back(name + ": not in the schema");
  }
  const nlohmann::json attributes = layout.value("attributes", nlohmann::json::object());
  for (auto it = attributes.begin(); it != attributes.end(); ++it) {
    if (it.value().value("type", "") != "json") continue;
    const nlohmann::json value = reader.ReadJson(it.key());
    if (it.value().contains("$ref")) {
      for (const auto& p : CheckJsonAgainstSchema(value, Dir(schema_path) + "/" +
                                                             it.value()["$ref"].get<std::string>()))
        problems.push_back("@" + it.key() + p.substr(1));
    }
  }
  return problems;
}

}  // namespace jvl::io
