// `litgs-engine run`: the stages of stage_table() in order, each in DIR/<stage>/ with a manifest.
//
// A stage is done when DIR/<stage>/manifest.json exists: it is written last, atomically, after the stage's
// outputs are complete, and holds the content hashes of its inputs and outputs and its options. A rerun skips
// a stage whose manifest matches (same inputs, options and command; outputs unchanged); any other stage runs
// again from an emptied folder, so results of different inputs never mix. --from forces a stage and those
// after it. A resumable stage (train) that was interrupted continues from its checkpoints when its inputs and
// options are those it started with (DIR/<stage>/started.json). DIR/run.json, rewritten after every stage,
// holds each stage's status, seconds, peak host memory and metrics.
#pragma once

#include <filesystem>
#include <nlohmann/json.hpp>
#include <ostream>
#include <stdexcept>
#include <string>

#include "host/run/run_config.h"

namespace litgs::host::run {

struct RunOptions {
  std::string input;
  std::filesystem::path out_dir;
  std::string from, until;  // stage names; "" for the first / last
  RunConfig config;
  std::filesystem::path engine;  // the litgs-engine binary that runs the stages' commands
  bool shared_stages = false;    // stage folders shared by runs in DIR/stages/ (StageContext::stage_rel)
  std::string record = "run";    // DIR/<record>.json and DIR/<record>.yaml: this run's record and options
};

// A stage that failed: the run stopped there; what earlier stages wrote is kept.
class StageFailed : public std::runtime_error {
 public:
  StageFailed(const std::string& stage, const std::string& why)
      : std::runtime_error("stage '" + stage + "' failed: " + why), stage_(stage) {}
  const std::string& stage() const { return stage_; }

 private:
  std::string stage_;
};

// Runs the pipeline, printing one progress line per stage and a summary to `out`; returns run.json's
// content. Throws StageFailed, or std::invalid_argument for a bad INPUT or stage name.
nlohmann::json run_pipeline(const RunOptions& options, std::ostream& out);

}  // namespace litgs::host::run
