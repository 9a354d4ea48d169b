// A stage of `litgs-engine run`: a small adapter that says what the stage reads (hashed into its manifest),
// which options it takes, which command does its work, and what it writes. Each stage is one file
// (stage_*.cc) and one row of the table in stage_table.cc; host/run/pipeline.h runs them.
#pragma once

#include <filesystem>
#include <functional>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "host/option_name.h"
#include "host/run/input_kind.h"
#include "host/run/run_config.h"

namespace litgs::host::run {

// What a stage sees: the run's input and options, and what the stages before it produced.
struct StageContext {
  std::filesystem::path input;
  InputKind kind = InputKind::kUnknown;
  std::filesystem::path out_dir;  // DIR
  std::filesystem::path engine;   // the litgs-engine binary the stages' commands run
  RunConfig config;
  nlohmann::json results = nlohmann::json::object();  // {stage: its result} of the stages done so far
  // Stages' folders are DIR/<stage>, or with shared_stages (ablate: runs that share what they can)
  // DIR/stages/<stage>-<hash of the INPUT and the options of this stage and those before it>, so runs whose
  // options agree up to a stage find it done.
  bool shared_stages = false;
  std::filesystem::path stage_rel(const std::string& stage) const;  // relative to DIR
  std::filesystem::path stage_dir(const std::string& stage) const { return out_dir / stage_rel(stage); }
  // The scene the next stage works on: the last "scene" among the results (import's, or the copy that map,
  // match or refine changed).
  std::filesystem::path scene() const;
};

// A stage that changes the scene works on its own copy, DIR/<stage>/scene: the files it rewrites are copied,
// the files it writes anew are left out, every other file is hard-linked (copied where links fail), so the
// previous stage's scene and the user's INPUT are never modified.
struct SceneCopy {
  std::filesystem::path from;      // the previous scene
  std::vector<std::string> copy;   // relative files or folders copied byte for byte
  std::vector<std::string> fresh;  // relative files or folders not carried over (the stage writes them)
};

// One stage's work as planned before it runs.
struct StagePlan {
  std::vector<std::filesystem::path> inputs;          // files or folders whose content decides a rerun
  nlohmann::json options = nlohmann::json::object();  // the options that decide a rerun
  std::vector<std::string> command;  // argv[1..] of `engine`; empty: nothing to run (result only)
  std::vector<std::filesystem::path>
      outputs;             // files or folders, relative to DIR (stage_rel), complete when it ends
  bool resumable = false;  // the command continues from its own checkpoints (train): not wiped on rerun
  std::vector<std::string> resume_args;  // added to the command when it continues
  // Relative to DIR: folders of which one must hold what the command continues from (a checkpoint, a
  // finished trial of the budget search).
  std::vector<std::filesystem::path> resume_from;
  std::string skip_reason;              // non-empty: nothing to do, reported as "skipped: REASON"
  std::vector<std::string> notes;       // printed with the stage's progress line and kept in run.json
  std::optional<SceneCopy> scene_copy;  // made in DIR/<stage>/scene before the command runs
};

struct Stage {
  std::string name;
  std::string what;  // one line for the progress display
  std::function<StagePlan(const StageContext&)> plan;
  // After the command succeeded (or when the stage is skipped as up to date): the stage's result for the
  // stages after it and its metrics for run.json, e.g. {"scene": path, "metrics": {...}}.
  std::function<nlohmann::json(const StageContext&)> result;
};

// A number as a command-line argument, without losing digits (std::to_string keeps 6 decimals).
std::string number_arg(double value);

// run.yaml options as command-line flags. Each spec is "key" (flag --key with '_' as '-') or "key=--flag";
// a bool adds its flag when true, or, with a flag written "!--flag", when false; a list of strings adds
// the flag and then each item; numbers keep every digit.
std::vector<std::string> option_flags(const nlohmann::json& section,
                                      std::initializer_list<const char*> specs);
// The same for options a command's table names (host/option_name.h): its key, then its flag.
std::vector<std::string> option_flags(const nlohmann::json& section, std::initializer_list<OptionName> names);

// A stage's JSON output (io::IoError naming the file when it is missing or malformed), and the listed keys
// of an object that it has (a stage's metrics).
nlohmann::json read_stage_json(const std::filesystem::path& path);
nlohmann::json pick(const nlohmann::json& object, std::initializer_list<const char*> keys);

// The plan of a stage that runs `litgs-engine STAGE DIR/<stage>/scene FLAGS... EXTRA...` on its own copy of
// the current scene (map, match, refine): the scene as input, the copy as `copied` and `fresh` say
// (SceneCopy), the copy as the output.
void plan_on_scene_copy(const StageContext& c, const std::string& stage, SceneCopy copy,
                        const std::vector<std::string>& flags, const std::vector<std::string>& extra_args,
                        StagePlan& p);

// Makes `to` (emptied first) a copy of copy.from as SceneCopy says. io::IoError naming a file that fails.
void make_scene_copy(const SceneCopy& copy, const std::filesystem::path& to);

// The stages in the order they run (stage_table.cc).
const std::vector<Stage>& stage_table();

// The stage adapters, one file each.
Stage import_stage();
Stage map_stage();
Stage match_stage();
Stage refine_stage();
Stage train_stage();
Stage eval_stage();
Stage report_stage();

}  // namespace litgs::host::run
