#include "scanner/sim/scene_fields.hpp"

#include <cstdio>

#include "scanner/common/error.hpp"

namespace uwscan::scanner::sim::scene_yaml {

std::string Num(double v) {
  char buffer[32];
  std::snprintf(buffer, sizeof(buffer), "%.9g", v);
  return buffer;
}

Context Item(const Context& where, size_t index) {
  return Context{where.source, where.path + "[" + std::to_string(index) + "]"};
}

bool Has(const YAML::Node& node, const std::string& key) {
  return node.IsMap() && node[key].IsDefined() && !node[key].IsNull();
}

[[noreturn]] void FailField(const Context& where, const YAML::Node& node, const std::string& key,
                            const std::string& what) {
  yaml::Fail(yaml::Enter(where, key), Has(node, key) ? node[key] : node, what);
}

bool Boolean(const Context& where, const YAML::Node& node, const std::string& key) {
  const YAML::Node child = yaml::Child(where, node, key);
  bool value = false;
  if (!child.IsScalar() || !YAML::convert<bool>::decode(child, value)) {
    FailField(where, node, key, "expected true or false");
  }
  return value;
}

std::string String(const Context& where, const YAML::Node& node, const std::string& key) {
  const YAML::Node child = yaml::Child(where, node, key);
  if (!child.IsScalar() || child.Scalar().empty()) FailField(where, node, key, "expected a name");
  return child.Scalar();
}

bool InRange(double v, Range range) {
  switch (range) {
    case Range::kPositive:
      return v > 0.0;
    case Range::kNonNegative:
      return v >= 0.0;
    case Range::kUnitInterval:
      return v >= 0.0 && v <= 1.0;
    case Range::kFraction:
      return v > 0.0 && v <= 1.0;
    case Range::kAtLeastOne:
      return v >= 1.0;
  }
  return false;
}

namespace {

const char* Expected(Range range) {
  switch (range) {
    case Range::kPositive:
      return "> 0";
    case Range::kNonNegative:
      return ">= 0";
    case Range::kUnitInterval:
      return "in [0, 1]";
    case Range::kFraction:
      return "in (0, 1]";
    case Range::kAtLeastOne:
      return ">= 1";
  }
  return "";
}

}  // namespace

double Number(const Context& where, const YAML::Node& node, const std::string& key, Range range,
              std::optional<double> fallback) {
  if (fallback && !Has(node, key)) return *fallback;
  const double value = yaml::Number(where, node, key);
  if (!InRange(value, range)) {
    FailField(where, node, key, "got " + Num(value) + ", expected " + Expected(range));
  }
  return value;
}

int Integer(const Context& where, const YAML::Node& node, const std::string& key, int minimum,
            std::optional<int> fallback) {
  if (fallback && !Has(node, key)) return *fallback;
  const int value = yaml::Integer(where, node, key);
  if (value < minimum) {
    FailField(where, node, key,
              "got " + std::to_string(value) + ", expected >= " + std::to_string(minimum));
  }
  return value;
}

void Checked(const Context& where, const YAML::Node& node, const std::function<void()>& check) {
  try {
    check();
  } catch (const Error& e) {
    yaml::Fail(where, node, e.what());
  }
}

std::filesystem::path Resolve(const std::filesystem::path& base_dir, const std::string& file) {
  const std::filesystem::path p(file);
  return (p.is_absolute() ? p : base_dir / p).lexically_normal();
}

}  // namespace uwscan::scanner::sim::scene_yaml
