#pragma once

// Typed, range-checked fields of scene files, on top of scanner/common/yaml_fields.hpp: every
// failure names "file:line: field 'a.b': ...". Included only by the scene readers.

#include <yaml-cpp/yaml.h>

#include <cstddef>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>

#include "scanner/common/yaml_fields.hpp"

namespace uwscan::scanner::sim::scene_yaml {

using yaml::Context;

// "%.9g": numbers in messages as the user would write them.
std::string Num(double v);

// The context of list element `index`: "objects" -> "objects[3]".
Context Item(const Context& where, size_t index);

// A key that is present and not null ("key:" with nothing after it counts as absent).
bool Has(const YAML::Node& node, const std::string& key);

// Fails at node[key] when it exists (its line), else at node.
[[noreturn]] void FailField(const Context& where, const YAML::Node& node, const std::string& key,
                            const std::string& what);

bool Boolean(const Context& where, const YAML::Node& node, const std::string& key);
std::string String(const Context& where, const YAML::Node& node, const std::string& key);

// What a number must be; the message says it.
enum class Range { kPositive, kNonNegative, kUnitInterval, kFraction, kAtLeastOne };

// A finite number in `range`; required unless a fallback is given.
double Number(const Context& where, const YAML::Node& node, const std::string& key, Range range,
              std::optional<double> fallback = std::nullopt);
bool InRange(double v, Range range);

// An integer >= minimum; required unless a fallback is given.
int Integer(const Context& where, const YAML::Node& node, const std::string& key, int minimum,
            std::optional<int> fallback = std::nullopt);

// Runs a Check() (or anything that throws uwscan::Error) and reports its message at `node`.
void Checked(const Context& where, const YAML::Node& node, const std::function<void()>& check);

// A path from a scene, relative to the scene's folder unless absolute.
std::filesystem::path Resolve(const std::filesystem::path& base_dir, const std::string& file);

}  // namespace uwscan::scanner::sim::scene_yaml
