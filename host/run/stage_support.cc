// What the stage adapters share: the current scene, run.yaml options as flags, the scene copies.
#include <cstdio>
#include <fstream>
#include <system_error>

#include "host/run/content_hash.h"
#include "host/run/stage.h"
#include "io/error.h"

namespace litgs::host::run {

namespace fs = std::filesystem;

fs::path StageContext::scene() const {
  fs::path scene;
  for (const Stage& stage : stage_table())  // in pipeline order (a JSON object's keys are sorted)
    if (results.contains(stage.name) && results[stage.name].contains("scene"))
      scene = results[stage.name]["scene"].get<std::string>();
  return scene;
}

fs::path StageContext::stage_rel(const std::string& stage) const {
  if (!shared_stages) return stage;
  const nlohmann::json sections = to_json(config);
  nlohmann::json prefix = {{"input", input.string()}};
  for (const Stage& s : stage_table()) {
    if (sections.contains(s.name)) prefix[s.name] = sections[s.name];
    if (s.name == stage) break;
  }
  return fs::path("stages") / (stage + "-" + hash_text(prefix.dump()));
}

std::string number_arg(double value) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.17g", value);
  return buf;
}

std::vector<std::string> option_flags(const nlohmann::json& section,
                                      std::initializer_list<const char*> specs) {
  std::vector<std::string> args;
  for (const std::string spec : specs) {
    const size_t eq = spec.find('=');
    const std::string key = spec.substr(0, eq);
    std::string flag = eq == std::string::npos ? "--" + key : spec.substr(eq + 1);
    if (eq == std::string::npos)
      for (char& c : flag)
        if (c == '_') c = '-';
    const nlohmann::json& v = section.at(key);
    if (v.is_boolean()) {
      const bool negated = flag.front() == '!';
      if (v.get<bool>() != negated) args.push_back(negated ? flag.substr(1) : flag);
    } else if (v.is_array()) {
      args.push_back(flag);
      for (const auto& item : v) args.push_back(item.get<std::string>());
    } else {
      args.push_back(flag);
      if (v.is_string()) {
        args.push_back(v.get<std::string>());
      } else if (v.is_number_float()) {
        args.push_back(number_arg(v.get<double>()));
      } else {
        args.push_back(v.dump());  // integers exactly
      }
    }
  }
  return args;
}

std::vector<std::string> option_flags(const nlohmann::json& section,
                                      std::initializer_list<OptionName> names) {
  std::vector<std::string> args;
  for (const OptionName& name : names) {
    const std::vector<std::string> one =
        option_flags(section, {(std::string(name.key) + "=" + name.flag).c_str()});
    args.insert(args.end(), one.begin(), one.end());
  }
  return args;
}

nlohmann::json read_stage_json(const fs::path& path) {
  std::ifstream in(path);
  if (!in) throw io::IoError(path, 0, "cannot open the stage's output");
  try {
    return nlohmann::json::parse(in);
  } catch (const nlohmann::json::exception& e) {
    throw io::IoError(path, 0, std::string("malformed JSON: ") + e.what());
  }
}

nlohmann::json pick(const nlohmann::json& object, std::initializer_list<const char*> keys) {
  nlohmann::json out = nlohmann::json::object();
  for (const char* key : keys)
    if (object.contains(key)) out[key] = object[key];
  return out;
}

namespace {

// True when `rel` is `prefix` or lies under it.
bool under(const fs::path& rel, const std::string& prefix) {
  const fs::path p(prefix);
  auto r = rel.begin();
  for (auto q = p.begin(); q != p.end(); ++q, ++r)
    if (r == rel.end() || *r != *q) return false;
  return true;
}

bool listed(const fs::path& rel, const std::vector<std::string>& prefixes) {
  for (const std::string& p : prefixes)
    if (under(rel, p)) return true;
  return false;
}

}  // namespace

void plan_on_scene_copy(const StageContext& c, const std::string& stage, SceneCopy copy,
                        const std::vector<std::string>& flags, const std::vector<std::string>& extra_args,
                        StagePlan& p) {
  p.inputs = {copy.from};
  p.command = {stage, (c.stage_dir(stage) / "scene").string()};
  p.command.insert(p.command.end(), flags.begin(), flags.end());
  p.command.insert(p.command.end(), extra_args.begin(), extra_args.end());
  p.outputs = {c.stage_rel(stage) / "scene"};
  p.scene_copy = std::move(copy);
}

void make_scene_copy(const SceneCopy& copy, const fs::path& to) {
  fs::remove_all(to);
  fs::create_directories(to);
  for (const auto& entry : fs::recursive_directory_iterator(copy.from)) {
    const fs::path rel = fs::relative(entry.path(), copy.from);
    if (listed(rel, copy.fresh)) continue;
    const fs::path dst = to / rel;
    std::error_code ec;
    if (entry.is_directory()) {
      fs::create_directories(dst, ec);
    } else if (entry.is_regular_file()) {
      bool linked = false;
      if (!listed(rel, copy.copy)) {
        fs::create_hard_link(entry.path(), dst, ec);
        linked = !ec;  // a link across file systems fails: copy instead
      }
      if (!linked) {
        ec.clear();
        fs::copy_file(entry.path(), dst, fs::copy_options::overwrite_existing, ec);
      }
    }
    if (ec) throw io::IoError(dst, 0, "cannot make the stage's copy of the scene: " + ec.message());
  }
}

}  // namespace litgs::host::run
