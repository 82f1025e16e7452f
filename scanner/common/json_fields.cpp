#include "scanner/common/json_fields.hpp"

#include <cmath>
#include <fstream>

#include "scanner/common/error.hpp"

namespace uwscan::json_fields {

using nlohmann::json;

void Field::Fail(const std::string& what) const { throw Error(file + ": " + path + ": " + what); }

json ParseJsonFile(const std::filesystem::path& path) {
  std::ifstream in(path);
  if (!in) throw Error(path.string() + ": cannot read");
  try {
    return json::parse(in);
  } catch (const json::exception& e) {
    throw Error(path.string() + ": not valid JSON (" + e.what() + ")");
  }
}

const json& Require(const json& object, const std::string& key, const Field& field) {
  const auto it = object.find(key);
  if (it == object.end()) field[key].Fail("missing");
  return *it;
}

std::vector<double> Numbers(const json& value, std::size_t count, const Field& field) {
  if (!value.is_array() || value.size() != count) {
    field.Fail("expected an array of " + std::to_string(count) + " numbers");
  }
  std::vector<double> numbers;
  for (std::size_t i = 0; i < count; ++i) {
    if (!value[i].is_number() || !std::isfinite(value[i].get<double>()))
      field[i].Fail("not a finite number");
    numbers.push_back(value[i].get<double>());
  }
  return numbers;
}

std::string ReportKind(const std::filesystem::path& path) {
  const json j = ParseJsonFile(path);
  if (!j.is_object()) return {};
  const auto kind = j.find("kind");
  return kind != j.end() && kind->is_string() ? kind->get<std::string>() : std::string();
}

void RequireFormatAndKind(const json& root, const std::string& kind, const Field& field) {
  if (!root.is_object()) field.Fail("expected a JSON object");
  const json& format = Require(root, "uwscan_format", field);
  if (!format.is_number_integer() || format.get<int>() != 1)
    field["uwscan_format"].Fail("this uwscan reads format 1");
  const json& k = Require(root, "kind", field);
  if (!k.is_string() || k.get<std::string>() != kind)
    field["kind"].Fail("expected \"" + kind + "\"");
}

}  // namespace uwscan::json_fields
