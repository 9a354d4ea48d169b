// `litgs-engine ablate INPUT --out DIR --study refine|lambda|features|strategy|all [--variants A,B]
// [--config run.yaml]`: the
// method's ablations as runs of the pipeline that share their common stages (host/run/ablate.h).
#include <CLI/CLI.hpp>
#include <iostream>
#include <memory>

#include "host/run/ablate.h"
#include "tools/commands.h"

namespace litgs::tools {

void add_ablate_command(CLI::App& app) {
  struct Options {
    std::string input, out, study = "all", variants, config, calib;
  };
  auto o = std::make_shared<Options>();
  CLI::App* cmd = app.add_subcommand(
      "ablate", "The method's ablations (refinement, lambda_geo, features, strategy) as Markdown tables");
  cmd->add_option("input", o->input, "As `run`'s INPUT (a scene directory, synth:PRESET, ...)")->required();
  cmd->add_option("--out", o->out, "Folder: DIR/stages/ (shared), DIR/runs/, DIR/ablation.md")->required();
  cmd->add_option("--study", o->study,
                  "refine | lambda | features | strategy | all, or several: refine,features")
      ->capture_default_str();
  cmd->add_option("--variants", o->variants,
                  "Only these runs of the studies, by name: sift-clahe,xfeat (default: all; a wrong name "
                  "lists them)");
  cmd->add_option("--config", o->config,
                  "run.yaml: the settings every run starts from (run's defaults, but max_gaussians 40000)")
      ->check(CLI::ExistingFile);
  cmd->add_option("--calib", o->calib, "ROS bag input: M2DGR calibration_results.txt")
      ->check(CLI::ExistingFile);
  cmd->callback([o] {
    host::run::AblateOptions a;
    a.input = o->input;
    a.out_dir = std::filesystem::absolute(o->out);
    a.study = o->study;
    a.variants = o->variants;
    if (!o->config.empty())
      a.config = host::run::read_run_config(o->config, host::run::ablation_base_config());
    if (!o->calib.empty()) a.config.import.calib = o->calib;
    a.engine = this_executable();
    std::string line = "litgs-engine ablate " + o->input + " --out " + o->out + " --study " + o->study;
    if (!o->variants.empty()) line += " --variants " + o->variants;
    if (!o->config.empty()) line += " --config " + o->config;
    if (!o->calib.empty()) line += " --calib " + o->calib;
    host::run::run_ablation(a, line, std::cout);
  });
}

}  // namespace litgs::tools
