// litgs-engine: one binary, one subcommand per job.
#include <CLI/CLI.hpp>
#include <iostream>
#include <string>

#include "engine/vk_check.h"
#include "tools/commands.h"

int main(int argc, char** argv) {
  CLI::App app{"litgs-engine: LiDAR-inertial-thermal Gaussian splatting on any Vulkan device"};
  // LITGS_VERSION comes from CMake's project(VERSION); --version needs no subcommand and no device.
  app.set_version_flag("--version", std::string("litgs-engine ") + LITGS_VERSION);
  app.require_subcommand(1);
  litgs::tools::add_info_command(app);
  litgs::tools::add_bench_command(app);
  litgs::tools::add_import_command(app);
  litgs::tools::add_render_command(app);
  litgs::tools::add_serve_command(app);
  litgs::tools::add_synth_command(app);
  litgs::tools::add_train_command(app);
  litgs::tools::add_eval_command(app);
  litgs::tools::add_run_command(app);
  litgs::tools::add_report_command(app);
  litgs::tools::add_ablate_command(app);
  litgs::tools::add_export_command(app);
  litgs::tools::add_match_command(app);
  litgs::tools::add_compare_frames_command(app);
  litgs::tools::add_map_command(app);
  litgs::tools::add_refine_command(app);
  litgs::tools::add_calib_command(app);
  litgs::tools::add_partition_command(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  } catch (const litgs::engine::NoDeviceError& e) {
    std::cerr << "litgs-engine: " << e.what() << "\n";
    return 3;
  } catch (const std::exception& e) {
    std::cerr << "litgs-engine: error: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
