// `litgs-engine match SCENE [--features orb|sift|akaze] [--no-clahe] [--pairs ...] [--max-keypoints K]
// [--threads T]`: the thermal front end; writes SCENE/sfm/ (docs/frontend.md). CPU only.
#include <CLI/CLI.hpp>
#include <chrono>
#include <iostream>
#include <memory>

#include "tools/commands.h"
#include "tools/frontend_cli.h"

namespace litgs::tools {

void add_match_command(CLI::App& app) {
  CLI::App* match = app.add_subcommand(
      "match",
      "Thermal front end: features, verified matches, tracks and points from the prior poses (SCENE/sfm/)");
  auto scene = std::make_shared<std::filesystem::path>();
  auto cli = std::make_shared<FrontendCli>();
  match->add_option("scene", *scene, "Scene directory")->required()->check(CLI::ExistingDirectory);
  add_frontend_options(*match, cli);
  match->callback([scene, cli] {
    const auto t0 = std::chrono::steady_clock::now();
    const host::frontend::FrontendResult r =
        host::frontend::run_frontend(*scene, cli->resolved(), progress_printer());
    host::frontend::write_frontend(*scene, r);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    print_summary(std::cout, "match", r);
    std::cout << "  written         " << (*scene / "sfm").string() << " (" << seconds << " s end to end)\n";
  });
}

}  // namespace litgs::tools
