#include "host/run/pipeline.h"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <fstream>
#include <map>
#include <sstream>

#include "host/run/child_process.h"
#include "host/run/content_hash.h"
#include "host/run/stage.h"
#include "host/run/stage_estimate.h"
#include "io/atomic_file.h"

namespace litgs::host::run {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

size_t stage_index(const std::string& name, size_t fallback) {
  if (name.empty()) return fallback;
  const auto& table = stage_table();
  for (size_t i = 0; i < table.size(); ++i)
    if (table[i].name == name) return i;
  std::string names;
  for (const Stage& s : table) names += (names.empty() ? "" : ", ") + s.name;
  throw std::invalid_argument("no stage named '" + name + "' (stages: " + names + ")");
}

json read_json(const fs::path& path) {
  std::ifstream in(path);
  if (!in) return nullptr;
  try {
    return json::parse(in);
  } catch (const json::exception&) {
    return nullptr;  // unreadable: as if absent (the stage runs again)
  }
}

void write_json(const fs::path& path, const json& j) {
  io::write_file_atomic(path, [&](std::ostream& s) { s << j.dump(2) << "\n"; });
}

std::string megabytes(uint64_t bytes) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.0f MB", static_cast<double>(bytes) / 1e6);
  return buf;
}

std::string now_text() {
  const std::time_t t = std::time(nullptr);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", std::gmtime(&t));
  return buf;
}

class Runner {
 public:
  Runner(const RunOptions& o, std::ostream& out) : o_(o), out_(out) {}

  json run() {
    const auto& table = stage_table();
    const size_t from = stage_index(o_.from, 0), until = stage_index(o_.until, table.size() - 1);
    if (from > until) throw std::invalid_argument("--from " + o_.from + " comes after --until " + o_.until);
    ctx_.input = o_.input;
    ctx_.kind = detect_input_kind(o_.input);
    if (ctx_.kind == InputKind::kUnknown)
      throw std::invalid_argument("INPUT '" + o_.input + "': unknown kind of input: " + input_kind_help());
    ctx_.out_dir = fs::absolute(o_.out_dir);
    ctx_.engine = o_.engine;
    ctx_.config = o_.config;
    ctx_.shared_stages = o_.shared_stages;
    record_path_ = ctx_.out_dir / (o_.record + ".json");
    fs::create_directories(record_path_.parent_path());
    // The run's options beside its results: `run INPUT --out DIR --config DIR/run.yaml` repeats it.
    io::write_file_atomic(ctx_.out_dir / (o_.record + ".yaml"),
                          [&](std::ostream& s) { s << run_config_yaml(o_.config); });
    record_ = {{"input", o_.input},
               {"kind", kind_name(ctx_.kind)},
               {"out", ctx_.out_dir.string()},
               {"config", to_json(o_.config)},
               {"started", now_text()},
               {"status", "running"},
               {"stages", json::array()}};
    const auto start = std::chrono::steady_clock::now();
    device_ = query_device(o_.engine);
    try {
      size_ = size_before_import(ctx_.kind, ctx_.input, o_.config);
    } catch (const std::exception&) {
      // A scene that cannot be read has no estimate: its import stage says what is wrong with it.
    }
    if (size_) print_estimates(from, until);
    for (size_t i = 0; i < table.size(); ++i) {
      const Stage& stage = table[i];
      json& entry = record_["stages"].emplace_back(json{{"name", stage.name}});
      const std::string tag =
          "run: [" + std::to_string(i + 1) + "/" + std::to_string(table.size()) + "] " + stage.name;
      if (i > until) {
        entry["status"] = "not run (after --until)";
        continue;
      }
      try {
        run_stage(stage, !o_.from.empty() && i >= from, tag, entry);
      } catch (const StageFailed&) {
        finish(start, "failed");
        throw;
      } catch (const std::exception& e) {
        entry["status"] = "failed";
        entry["reason"] = e.what();
        finish(start, "failed");
        throw StageFailed(stage.name, e.what());
      }
      write_json(record_path_, record_);
      if (stage.name == "import" && !size_) {
        // Only the import knows a recording's size: the stages after it are estimated now.
        try {
          size_ = size_of_scene(ctx_.scene());
          print_estimates(i + 1, until);
        } catch (const std::exception&) {
          // No estimates: the next stage reads the scene and names what is wrong with it.
        }
      }
    }
    finish(start, "done");
    summary();
    return record_;
  }

 private:
  std::string hash_of(const fs::path& p) {
    const std::string key = fs::absolute(p).string();
    auto it = hashes_.find(key);
    if (it == hashes_.end()) it = hashes_.emplace(key, hash_path(p)).first;
    return it->second;
  }

  json output_hashes(const StagePlan& plan) {
    json h = json::object();
    for (const fs::path& p : plan.outputs) h[p.generic_string()] = hash_path(ctx_.out_dir / p);
    return h;
  }

  // True when the manifest says the stage is done with these inputs and options, and its outputs are as it
  // left them.
  bool up_to_date(const json& manifest, const std::string& key, const StagePlan& plan) {
    if (!manifest.is_object() || manifest.value("key", "") != key) return false;
    try {
      return manifest.at("outputs") == output_hashes(plan);
    } catch (const std::exception&) {
      return false;  // an output is missing or unreadable
    }
  }

  void run_stage(const Stage& stage, bool forced, const std::string& tag, json& entry) {
    const StagePlan plan = stage.plan(ctx_);
    const fs::path dir = ctx_.stage_dir(stage.name), manifest_path = dir / "manifest.json";
    if (!plan.skip_reason.empty()) {
      // Nothing to do: what an earlier run left there would be taken for this run's.
      fs::remove_all(dir);
      ctx_.results[stage.name] = {{"skipped", plan.skip_reason}};
      entry["status"] = "skipped: " + plan.skip_reason;
      out_ << tag << ": skipped: " << plan.skip_reason << "\n";
      return;
    }
    if (!plan.notes.empty()) entry["notes"] = plan.notes;
    json inputs = json::object();
    for (const fs::path& p : plan.inputs) inputs[fs::absolute(p).string()] = hash_of(p);
    // The engine is an input too: a stage made by another build (other defaults, other code) is not this
    // build's, so a rebuilt or upgraded engine runs its stages again.
    const std::string engine = hash_of(ctx_.engine);
    const std::string key = hash_text(json{
        {"stage", stage.name},
        {"engine", engine},
        {"inputs", inputs},
        {"options", plan.options},
        {"command", plan.command}}.dump());
    const json manifest = read_json(manifest_path);
    if (!forced && up_to_date(manifest, key, plan)) {
      ctx_.results[stage.name] = manifest.at("result");
      entry.update({{"status", "up to date"},
                    {"seconds", manifest.value("seconds", 0.0)},
                    {"peak_host_bytes", manifest.value("peak_host_bytes", 0)},
                    {"metrics", manifest.at("result").value("metrics", json::object())}});
      out_ << tag << ": up to date (manifest matches), skipped\n";
      return;
    }
    // Continue an interrupted resumable stage only if it started with these inputs and options.
    const json started = read_json(dir / "started.json");
    // Only from a checkpoint (or a finished trial of the budget search): one killed, or out of disk space,
    // before its first has nothing to continue.
    std::string continue_from;  // the folders holding work to continue, named in the stage's line
    for (const fs::path& rel : plan.resume_from) {
      const fs::path folder = ctx_.out_dir / rel;
      if (fs::is_directory(folder) && !fs::is_empty(folder))
        continue_from += (continue_from.empty() ? "" : " and ") + rel.generic_string();
    }
    const bool resume = plan.resumable && !forced && started.is_object() && started.value("key", "") == key &&
                        !continue_from.empty();
    if (!resume) fs::remove_all(dir);
    fs::remove(manifest_path);
    fs::create_directories(dir);
    write_json(dir / "started.json", {{"key", key}, {"started", now_text()}});
    if (plan.scene_copy && !resume) make_scene_copy(*plan.scene_copy, dir / "scene");
    std::vector<std::string> command = plan.command;
    if (resume) command.insert(command.end(), plan.resume_args.begin(), plan.resume_args.end());
    out_ << tag << ": " << stage.what << (resume ? " (resuming from " + continue_from + ")" : "")
         << (forced ? " (forced by --from)" : "") << "\n";
    if (const auto e = estimate(stage.name); e && e->high_s > 0) {
      entry["estimate_s"] = {e->low_s, e->high_s};
      out_ << tag << ": estimate: " << estimate_text(*e) << " (" << e->basis << ")\n";
    }
    for (const std::string& note : plan.notes) out_ << tag << ": note: " << note << "\n";
    out_ << std::flush;
    ChildResult child;
    if (!command.empty()) {
      child = run_child(ctx_.engine, command, dir / "log.txt", out_);
      if (child.exit_code != 0) {
        std::string why = child.signal ? "killed by signal " + std::to_string(child.signal)
                                       : "exit status " + std::to_string(child.exit_code);
        const std::string last = last_line(child.tail);
        if (!last.empty()) why += ": " + last;
        entry.update({{"status", "failed"}, {"reason", why}, {"seconds", child.seconds}});
        out_ << tag << ": FAILED (" << why << "); log: " << (dir / "log.txt").string()
             << "; earlier stages' outputs are kept\n";
        throw StageFailed(stage.name, why);
      }
    }
    const json result = stage.result(ctx_);
    ctx_.results[stage.name] = result;
    // Written last: until it exists, the stage is not done.
    write_json(manifest_path, {{"stage", stage.name},
                               {"key", key},
                               {"engine", {{"path", ctx_.engine.string()}, {"hash", engine}}},
                               {"inputs", inputs},
                               {"options", plan.options},
                               {"command", plan.command},
                               {"outputs", output_hashes(plan)},
                               {"result", result},
                               {"seconds", child.seconds},
                               {"peak_host_bytes", child.peak_host_bytes},
                               {"finished", now_text()}});
    entry.update({{"status", "done"},
                  {"seconds", child.seconds},
                  {"peak_host_bytes", child.peak_host_bytes},
                  {"metrics", result.value("metrics", json::object())}});
    if (resume) entry["resumed"] = true;
    char line[128];
    std::snprintf(line, sizeof line, ": done in %.1f s, peak host memory %s\n", child.seconds,
                  megabytes(child.peak_host_bytes).c_str());
    out_ << tag << line;
  }

  std::optional<StageEstimate> estimate(const std::string& stage) const {
    if (!size_) return std::nullopt;
    return estimate_stage(stage, ctx_.kind, *size_, o_.config, device_);
  }

  // One line before the stages from..until run: what each will cost, as far as the size is known.
  void print_estimates(size_t from, size_t until) {
    const auto& table = stage_table();
    std::string line;
    double low = 0, high = 0;
    for (size_t i = from; i <= until && i < table.size(); ++i) {
      std::string why;
      const auto e = estimate_stage(table[i].name, ctx_.kind, *size_, o_.config, device_, &why);
      if (e && e->high_s == 0) continue;  // nothing to do
      line += (line.empty() ? "" : ", ") + table[i].name + " " + (e ? estimate_text(*e) : "? (" + why + ")");
      if (e) low += e->low_s, high += e->high_s;
    }
    if (line.empty()) return;
    out_ << "run: estimate (from the scene's size and the device; an estimate, not a promise): " << line
         << "; stages that turn out up to date or skipped take less; in all "
         << estimate_text({low, high, ""}) << "\n"
         << std::flush;
  }

  // The child's last line that says something: CLI11's "Run with --help" hint is skipped.
  static std::string last_line(const std::string& text) {
    std::istringstream in(text);
    std::string line, last;
    while (std::getline(in, line)) {
      while (!line.empty() && (line.back() == '\r' || line.back() == ' ')) line.pop_back();
      if (!line.empty() && line.rfind("Run with --help", 0) != 0) last = line;
    }
    return last;
  }

  void finish(std::chrono::steady_clock::time_point start, const std::string& status) {
    record_["status"] = status;
    record_["total_seconds"] =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    write_json(record_path_, record_);
  }

  void summary() {
    out_ << "run: summary (" << (record_path_).string() << ")\n";
    for (const json& s : record_["stages"]) {
      char line[256];
      std::string status = s["status"].get<std::string>();
      // refine says what it did, as the report's stage table does: refined, kept the priors or stopped.
      if (const json m = s.value("metrics", json::object()); m.is_object() && m.contains("outcome"))
        status += ": " + m["outcome"].get<std::string>();
      std::snprintf(line, sizeof line, "  %-8s %-24s", s["name"].get<std::string>().c_str(), status.c_str());
      out_ << line;
      if (s.contains("seconds")) {
        std::snprintf(line, sizeof line, " %8.1f s, peak host memory %s", s["seconds"].get<double>(),
                      megabytes(s.value("peak_host_bytes", uint64_t{0})).c_str());
        out_ << line;
      }
      if (s.contains("estimate_s"))
        out_ << " (estimated " << estimate_text({s["estimate_s"][0], s["estimate_s"][1], ""}) << ")";
      out_ << "\n";
    }
    const json& results = ctx_.results;
    if (results.contains("eval")) {
      const json& m = results["eval"]["metrics"];
      const auto value = [&](const char* key) {
        return m.value(key, json()).is_number() ? m[key].get<double>() : NAN;
      };
      char line[256];
      std::snprintf(line, sizeof line,
                    "run: held-out PSNR %.2f dB, SSIM %.4f, EMD %.4f m (sampling floor %.4f m), "
                    "render %.1f ms/frame, %.0f Gaussians\n",
                    value("psnr_db"), value("ssim"), value("emd_m"), value("emd_floor_m"),
                    value("render_ms_per_frame"), value("gaussians"));
      out_ << line;
      if (m.value("observed_fraction", json()).is_number()) {
        std::snprintf(line, sizeof line,
                      "run: EMD over the region the training views see: %.1f%% of the reference, %.1f%% of "
                      "it within reach of a Gaussian\n",
                      100 * value("observed_fraction"), 100 * value("covered_fraction"));
        out_ << line;
      }
      if (m.value("covisible_psnr_db", json()).is_number()) {
        std::snprintf(line, sizeof line,
                      "run: held-out PSNR %.2f dB on the %.1f%% of pixels a training view saw\n",
                      value("covisible_psnr_db"), 100 * value("covisible_fraction"));
        out_ << line;
      }
      if (m.value("ate_m", json()).is_number()) {
        std::snprintf(line, sizeof line, "run: ATE %.4f m", value("ate_m"));
        out_ << line;
        if (m["ate_prior_m"].is_number()) {
          std::snprintf(line, sizeof line, " (before refinement %.4f m)", value("ate_prior_m"));
          out_ << line;
        }
        out_ << " against gt/poses.txt\n";
      }
    }
    if (results.contains("report"))
      out_ << "run: report: " << results["report"]["report"].get<std::string>() << "\n";
  }

  const RunOptions& o_;
  std::ostream& out_;
  StageContext ctx_;
  json record_;
  fs::path record_path_;  // DIR/run.json
  EstimateDevice device_;
  std::optional<RunSize> size_;  // unknown before a recording's import
  std::map<std::string, std::string> hashes_;
};

}  // namespace

nlohmann::json run_pipeline(const RunOptions& options, std::ostream& out) {
  return Runner(options, out).run();
}

}  // namespace litgs::host::run
