// `litgs-engine bench frontend SCENE [front-end options]`: the front end with the given options (default:
// SIFT, CLAHE, covisible pairs, the prior epipolar bound, grid bucketing) against a plain exhaustive
// baseline in the same run (SIFT without CLAHE, every pair, MAGSAC only, strongest keypoints without a
// grid; same budget, ratio and triangulation). Writes nothing.
#include <CLI/CLI.hpp>
#include <iomanip>
#include <iostream>
#include <memory>

#include "tools/commands.h"
#include "tools/frontend_cli.h"

namespace litgs::tools {

void add_bench_frontend_command(CLI::App& bench) {
  CLI::App* cmd = bench.add_subcommand("frontend", "The front end against a plain exhaustive baseline");
  auto scene = std::make_shared<std::filesystem::path>();
  auto cli = std::make_shared<FrontendCli>();
  auto skip_baseline = std::make_shared<bool>(false);
  cmd->add_option("scene", *scene, "Scene directory")->required()->check(CLI::ExistingDirectory);
  add_frontend_options(*cmd, cli);
  cmd->add_flag("--no-baseline", *skip_baseline, "Run only the configured front end");
  cmd->callback([scene, cli, skip_baseline] {
    const host::frontend::FrontendOptions chosen = cli->resolved();
    if (!*skip_baseline) {
      host::frontend::FrontendOptions base = chosen;
      base.features.type = host::frontend::FeatureType::kSift;
      base.features.grid_cols = base.features.grid_rows = 0;
      base.preprocess.clahe = false;
      base.pairs.mode = host::frontend::PairMode::kExhaustive;
      base.prior_epipolar = false;
      const auto b = host::frontend::run_frontend(*scene, base, progress_printer());
      print_summary(std::cout, "baseline", b);
    }
    const auto r = host::frontend::run_frontend(*scene, chosen, progress_printer());
    print_summary(std::cout, "front end", r);
  });
}

}  // namespace litgs::tools
