#include "host/run/run_config.h"

#include <yaml-cpp/yaml.h>

#include <charconv>
#include <cmath>
#include <limits>
#include <set>

#include "io/error.h"

namespace litgs::host::run {
namespace {

// One value from YAML into a field of its type; a message naming what was expected otherwise.
void assign(const YAML::Node& node, std::string& value) {
  if (!node.IsScalar()) throw std::invalid_argument("expected a string");
  value = node.as<std::string>();
}
void assign(const YAML::Node& node, uint32_t& value) {
  long long v = 0;
  if (!node.IsScalar() || !YAML::convert<long long>::decode(node, v) || v < 0 ||
      v > std::numeric_limits<uint32_t>::max())
    throw std::invalid_argument("expected a whole number from 0 to 4294967295");
  value = static_cast<uint32_t>(v);
}
void assign(const YAML::Node& node, double& value) {
  if (!node.IsScalar() || !YAML::convert<double>::decode(node, value) || !std::isfinite(value))
    throw std::invalid_argument("expected a finite number");
}
void assign(const YAML::Node& node, bool& value) {
  if (!node.IsScalar() || !YAML::convert<bool>::decode(node, value))
    throw std::invalid_argument("expected true or false");
}
void assign(const YAML::Node& node, std::vector<std::string>& value) {
  if (!node.IsSequence()) throw std::invalid_argument("expected a list of strings, e.g. [a, b]");
  value.clear();
  for (const YAML::Node& item : node) {
    if (!item.IsScalar()) throw std::invalid_argument("expected a list of strings, e.g. [a, b]");
    value.push_back(item.as<std::string>());
  }
}

// YAML text of a value (strings quoted so that "", "yes" or "1e3" stay strings).
std::string quoted(const std::string& s) {
  std::string out = "\"";
  for (char c : s) {
    if (c == '"' || c == '\\') out += '\\';
    out += c;
  }
  return out + "\"";
}
std::string yaml_text(const std::string& v) {
  return quoted(v);
}
std::string yaml_text(uint32_t v) {
  return std::to_string(v);
}
std::string yaml_text(double v) {
  // The shortest text that reads back as the same double (0.3, not 0.29999999999999999).
  char text[32];
  const auto end = std::to_chars(text, text + sizeof text, v).ptr;
  return std::string(text, end);
}
std::string yaml_text(bool v) {
  return v ? "true" : "false";
}
std::string yaml_text(const std::vector<std::string>& v) {
  std::string out = "[";
  for (size_t i = 0; i < v.size(); ++i) out += (i ? ", " : "") + quoted(v[i]);
  return out + "]";
}

}  // namespace

RunConfig read_run_config(const std::filesystem::path& path, const RunConfig& base) {
  YAML::Node root;
  try {
    root = YAML::LoadFile(path.string());
  } catch (const YAML::BadFile&) {
    throw io::IoError(path, 0, "cannot open the run configuration");
  } catch (const YAML::Exception& e) {
    throw io::IoError(path, e.mark.line + 1, "YAML error: " + e.msg);
  }
  RunConfig config = base;
  if (root.IsNull()) return config;  // an empty file: every default
  if (!root.IsMap())
    throw io::IoError(path, 0, "expected sections (import, map, match, refine, train, eval, report)");
  std::set<std::string> sections, known;
  for_each_field(config, [&](const char* section, const char* key, auto&, const char*) {
    sections.insert(section);
    known.insert(std::string(section) + "." + key);
  });
  std::set<std::string> seen_sections;
  for (const auto& s : root) {
    const std::string section = s.first.as<std::string>();
    const int line = s.first.Mark().line + 1;
    if (!seen_sections.insert(section).second)
      throw io::IoError(path, line, "section '" + section + "' given twice");
    if (!sections.count(section))
      throw io::IoError(
          path, line,
          "unknown section '" + section + "' (sections: import, map, match, refine, train, eval, report)");
    if (s.second.IsNull()) continue;
    if (!s.second.IsMap()) throw io::IoError(path, line, "section '" + section + "' must hold keys");
    std::set<std::string> seen;
    for (const auto& k : s.second) {
      const std::string key = k.first.as<std::string>();
      if (!seen.insert(key).second)
        throw io::IoError(path, k.first.Mark().line + 1, "key '" + section + "." + key + "' given twice");
      if (!known.count(section + "." + key))
        throw io::IoError(path, k.first.Mark().line + 1,
                          "unknown key '" + section + "." + key + "' (run --print-config lists every key)");
    }
  }
  for_each_field(config, [&](const char* section, const char* key, auto& value, const char*) {
    // Read through a const node: a non-const operator[] would insert the missing keys it is asked for.
    const YAML::Node& read_only = root;
    if (!read_only[section] || !read_only[section].IsMap()) return;
    const YAML::Node node = read_only[section][key];
    if (!node.IsDefined()) return;
    try {
      assign(node, value);
    } catch (const std::exception& e) {
      throw io::IoError(path, node.Mark().line + 1, std::string(section) + "." + key + ": " + e.what());
    }
  });
  return config;
}

std::string run_config_yaml(const RunConfig& config) {
  std::string out =
      "# run.yaml: the options of `litgs-engine run INPUT --out DIR --config run.yaml`. Every key is "
      "optional\n"
      "# (its default is shown); unknown keys are errors.\n";
  std::string current;
  for_each_field(config, [&](const char* section, const char* key, const auto& value, const char* comment) {
    if (current != section) {
      current = section;
      out += std::string(section) + ":\n";
    }
    out += "  # " + std::string(comment) + "\n  " + key + ": " + yaml_text(value) + "\n";
  });
  return out;
}

nlohmann::json to_json(const RunConfig& config) {
  nlohmann::json j = nlohmann::json::object();
  for_each_field(config, [&](const char* section, const char* key, const auto& value, const char*) {
    j[section][key] = value;
  });
  return j;
}

nlohmann::json section_json(const RunConfig& config, const std::string& section) {
  return to_json(config).at(section);
}

}  // namespace litgs::host::run
