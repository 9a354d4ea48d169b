// The subcommands of litgs-engine. Each registers itself on the CLI11 app and runs when chosen.
#pragma once

#include <filesystem>
#include <string>

namespace CLI {
class App;
}
namespace litgs::host {
struct LidarMapReport;
}

namespace litgs::tools {

void add_info_command(CLI::App& app);
void add_bench_command(CLI::App& app);  // bench sort | render | gather | loss | serve | frontend | features
void add_bench_sort_command(CLI::App& bench);
void add_bench_features_command(CLI::App& bench);
void add_bench_render_command(CLI::App& bench);
void add_bench_gather_command(CLI::App& bench);
void add_bench_loss_command(CLI::App& bench);
void add_bench_serve_command(CLI::App& bench);
void add_bench_frontend_command(CLI::App& bench);
void add_import_command(CLI::App& app);  // import metashape | colmap | livo2 | bag
void add_export_command(CLI::App& app);  // export colmap | tum | splat
void add_render_command(CLI::App& app);
void add_serve_command(CLI::App& app);
void add_synth_command(CLI::App& app);
void add_train_command(CLI::App& app);
void add_match_command(CLI::App& app);
void add_compare_frames_command(CLI::App& app);  // tools/cmd_compare_frames.cc
void add_map_command(CLI::App& app);
void add_refine_command(CLI::App& app);
void print_lidar_map_report(const host::LidarMapReport& report, const std::string& where);  // cmd_map.cc
void add_eval_command(CLI::App& app);
void add_run_command(CLI::App& app);  // and its report: tools/cmd_run.cc
void add_report_command(CLI::App& app);
void add_ablate_command(CLI::App& app);     // tools/cmd_ablate.cc
void add_partition_command(CLI::App& app);  // partition and merge: tools/cmd_partition.cc
void add_calib_command(CLI::App& app);      // calib intrinsics: tools/cmd_calib.cc
// This program's path ($LITGS_ENGINE where set, else /proc/self/exe): `run` and `ablate` run their stages
// with it.
std::filesystem::path this_executable();

}  // namespace litgs::tools
