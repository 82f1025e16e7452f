#pragma once
// Reading the JSON files uwscan writes (map and recognition reports) with
// errors that name the file and the field.

#include <cstddef>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace uwscan::json_fields {

// A place in a JSON file, for errors such as "report.json: trajectories.slam[3]: ...".
struct Field {
  const std::string& file;
  std::string path;
  [[noreturn]] void Fail(const std::string& what) const;
  Field operator[](const std::string& key) const {
    return {file, path.empty() ? key : path + "." + key};
  }
  Field operator[](std::size_t i) const { return {file, path + "[" + std::to_string(i) + "]"}; }
};

// The file parsed; throws uwscan::Error naming it when it cannot be read or is not JSON.
nlohmann::json ParseJsonFile(const std::filesystem::path& path);
// object[key]; fails naming the field when it is missing.
const nlohmann::json& Require(const nlohmann::json& object, const std::string& key,
                              const Field& field);
// An array of exactly `count` finite numbers.
std::vector<double> Numbers(const nlohmann::json& value, std::size_t count, const Field& field);
// The "kind" a report says it is; empty when the file is not a JSON object with a string
// "kind". Throws uwscan::Error naming the file when it cannot be read or is not JSON.
std::string ReportKind(const std::filesystem::path& path);
// Fails unless the root holds "uwscan_format": 1 and "kind": `kind`.
void RequireFormatAndKind(const nlohmann::json& root, const std::string& kind, const Field& field);

}  // namespace uwscan::json_fields
