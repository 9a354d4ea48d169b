// `litgs-engine bench ...`: benchmarks that print figures, against a baseline measured in the same run.
#include <CLI/CLI.hpp>

#include "tools/commands.h"

namespace litgs::tools {

void add_bench_command(CLI::App& app) {
  CLI::App* bench = app.add_subcommand("bench", "Benchmarks that print figures against a baseline");
  bench->require_subcommand(1);
  add_bench_sort_command(*bench);
  add_bench_render_command(*bench);
  add_bench_gather_command(*bench);
  add_bench_loss_command(*bench);
  add_bench_serve_command(*bench);
  add_bench_frontend_command(*bench);
  add_bench_features_command(*bench);
}

}  // namespace litgs::tools
