// Helpers of the `litgs-engine run` tests: a small synthetic run configuration, run.json access, shell calls.
#pragma once

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "engine_cli.h"

namespace litgs::testing {

// The tests' run.yaml: a 16-frame 64x48 facade, `iterations` from 3,000 random Gaussians, small EMD draws;
// `train_extra`: more lines of the train section.
inline std::string small_run_yaml(const std::string& train_extra = "", int iterations = 40) {
  return "import:\n  synth_frames: 16\n  synth_width: 64\n  synth_height: 48\n"
         "train:\n  iterations: " +
         std::to_string(iterations) +
         "\n  init: random\n  max_gaussians: 3000\n  eval_every: 20\n"
         "  checkpoint_every: 20\n  progress_every: 10\n  holdout_every: 4\n"
         "  extra_args: [\"--random-count\", \"3000\"]\n" +
         train_extra + "eval:\n  emd_samples: 200\n  emd_rounds: 2\n" +
         // The front end finds almost nothing on 64x48 frames: tracks projected from the scene's truth (an
         // experiment's option; these tests check the pipeline, not the refinement's accuracy).
         "refine:\n  tracks: oracle\n";
}

inline std::filesystem::path write_text(const std::filesystem::path& path, const std::string& text) {
  std::filesystem::create_directories(path.parent_path());
  std::ofstream(path) << text;
  return path;
}

inline nlohmann::json read_json_file(const std::filesystem::path& path) {
  std::ifstream in(path);
  if (!in) return nullptr;
  return nlohmann::json::parse(in, nullptr, false);
}

// The status run.json gives `stage` ("" when the stage is not listed).
inline std::string stage_status(const std::filesystem::path& dir, const std::string& record,
                                const std::string& stage) {
  const nlohmann::json run = read_json_file(dir / (record + ".json"));
  if (!run.is_object()) return "";
  for (const auto& s : run["stages"])
    if (s["name"] == stage) return s.value("status", "");
  return "";
}
inline std::string stage_status(const std::filesystem::path& dir, const std::string& stage) {
  return stage_status(dir, "run", stage);
}

}  // namespace litgs::testing
