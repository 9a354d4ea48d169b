// `litgs-engine compare-frames REFERENCE SCENE [front-end options] [--json]`: how matchable two scenes'
// thermal frames are, side by side (host/frontend/appearance.h). Nothing is written.
#include <CLI/CLI.hpp>
#include <iostream>
#include <memory>

#include "host/frontend/appearance.h"
#include "tools/commands.h"
#include "tools/frontend_cli.h"

namespace litgs::tools {

void add_compare_frames_command(CLI::App& app) {
  CLI::App* c = app.add_subcommand(
      "compare-frames",
      "Compare two scenes' thermal frames: gradient histograms, keypoints per image, inlier ratio");
  auto reference = std::make_shared<std::filesystem::path>();
  auto scene = std::make_shared<std::filesystem::path>();
  auto json = std::make_shared<bool>(false);
  auto cli = std::make_shared<FrontendCli>();
  c->add_option("reference", *reference, "Reference scene (e.g. real frames)")
      ->required()
      ->check(CLI::ExistingDirectory);
  c->add_option("scene", *scene, "Scene to compare with it")->required()->check(CLI::ExistingDirectory);
  c->add_flag("--json", *json, "One JSON object instead of the table");
  add_frontend_options(*c, cli);
  c->callback([reference, scene, json, cli] {
    const auto options = cli->resolved();
    const auto r = host::frontend::measure_appearance(*reference, options);
    const auto s = host::frontend::measure_appearance(*scene, options);
    std::cout << (*json ? host::frontend::compare_appearance_json(r, s) + "\n"
                        : host::frontend::compare_appearance_text(r, s));
  });
}

}  // namespace litgs::tools
