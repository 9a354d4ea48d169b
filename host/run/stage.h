// A stage of `litgs-engine run`: a small adapter that says what the stage reads (hashed into its manifest),
// which options it takes, which command does its work, and what it writes. Each stage is one file
// (stage_*.cc) and one row of the table in stage_table.cc; host/run/pipeline.h runs them.
#pragma once

#include <filesystem>
#include <functional>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

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
  std::filesystem::path stage_dir(const std::string& stage) const { return out_dir / stage; }
};

// One stage's work as planned before it runs.
struct StagePlan {
  std::vector<std::filesystem::path> inputs;          // files or folders whose content decides a rerun
  nlohmann::json options = nlohmann::json::object();  // the options that decide a rerun
  std::vector<std::string> command;            // argv[1..] of `engine`; empty: nothing to run (result only)
  std::vector<std::filesystem::path> outputs;  // files or folders, relative to DIR, complete when it ends
  bool resumable = false;  // the command continues from its own checkpoints (train): not wiped on rerun
  std::vector<std::string> resume_args;  // added to the command when it continues
};

struct Stage {
  std::string name;
  std::string what;   // one line for the progress display
  bool built = true;  // false: reported as "skipped: not built yet", never run
  std::function<StagePlan(const StageContext&)> plan;
  // After the command succeeded (or when the stage is skipped as up to date): the stage's result for the
  // stages after it and its metrics for run.json, e.g. {"scene": path, "metrics": {...}}.
  std::function<nlohmann::json(const StageContext&)> result;
};

// A number as a command-line argument, without losing digits (std::to_string keeps 6 decimals).
std::string number_arg(double value);

// The stages in the order they run (stage_table.cc).
const std::vector<Stage>& stage_table();

// The stage adapters, one file each.
Stage import_stage();
Stage train_stage();
Stage eval_stage();
Stage report_stage();
Stage not_built_stage(const std::string& name, const std::string& what);

}  // namespace litgs::host::run
