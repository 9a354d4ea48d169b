// `litgs-engine run INPUT --out DIR`: from the data to a map, its metrics and a report, as resumable stages
// (host/run/pipeline.h); `litgs-engine report --run DIR`: the report of a run folder alone.
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <climits>
#include <cstdlib>
#include <iostream>
#include <memory>

#include "host/run/pipeline.h"
#include "host/run/report_html.h"
#include "io/atomic_file.h"
#include "tools/commands.h"

namespace litgs::tools {
namespace {

struct RunCliOptions {
  std::string input, out, from, until, config, calib;
  bool print_config = false;
};

void run_run(const RunCliOptions& o) {
  host::run::RunConfig config;
  if (!o.config.empty()) config = host::run::read_run_config(o.config);
  if (!o.calib.empty()) config.import.calib = o.calib;
  if (o.print_config) {
    std::cout << host::run::run_config_yaml(config);
    return;
  }
  if (o.input.empty() || o.out.empty()) throw std::invalid_argument("run needs INPUT and --out DIR");
  host::run::RunOptions r{o.input, o.out, o.from, o.until, config, this_executable()};
  host::run::run_pipeline(r, std::cout);
}

}  // namespace

std::filesystem::path this_executable() {
  // Started through a wrapper (ci/gpu-bundle-run starts the engine with a bundled loader, so /proc/self/exe
  // names the loader), the wrapper says which program to run.
  if (const char* engine = std::getenv("LITGS_ENGINE"); engine && *engine) return engine;
  char buf[PATH_MAX];
  const ssize_t n = ::readlink("/proc/self/exe", buf, sizeof buf - 1);
  if (n <= 0) throw std::runtime_error("cannot find this program's path (/proc/self/exe)");
  return std::string(buf, static_cast<size_t>(n));
}

void add_run_command(CLI::App& app) {
  auto o = std::make_shared<RunCliOptions>();
  CLI::App* cmd = app.add_subcommand(
      "run", "Import, train, evaluate and report in one resumable pipeline (DIR/<stage>/, DIR/run.json)");
  cmd->add_option(
      "input", o->input,
      "Scene directory, ROS bag (.bag, with --calib), FAST-LIVO2 Log folder, Metashape XML, COLMAP "
      "model folder, or synth:PRESET");
  cmd->add_option("--out", o->out, "Run folder: DIR/<stage>/, DIR/run.json, DIR/report.html");
  cmd->add_option("--from", o->from, "Run this stage and those after it again, even if up to date");
  cmd->add_option("--until", o->until, "Stop after this stage");
  cmd->add_option("--config", o->config, "run.yaml (run --print-config prints every option with its default)")
      ->check(CLI::ExistingFile);
  cmd->add_option("--calib", o->calib, "ROS bag input: M2DGR calibration_results.txt (import.calib)")
      ->check(CLI::ExistingFile);
  cmd->add_flag("--print-config", o->print_config, "Print the options (defaults, or --config's) as run.yaml");
  cmd->callback([o] { run_run(*o); });
}

void add_report_command(CLI::App& app) {
  struct Options {
    std::string run, out;
    unsigned max_views = 4;
  };
  auto o = std::make_shared<Options>();
  CLI::App* cmd = app.add_subcommand("report", "Write the self-contained HTML report of a run folder");
  cmd->add_option("--run", o->run, "Run folder (train/ and eval/ done)")
      ->required()
      ->check(CLI::ExistingDirectory);
  cmd->add_option("--out", o->out, "HTML file (default: RUN/report.html)");
  cmd->add_option("--max-views", o->max_views, "Held-out views shown as pictures")->capture_default_str();
  cmd->callback([o] {
    const std::filesystem::path out =
        o->out.empty() ? std::filesystem::path(o->run) / "report.html" : std::filesystem::path(o->out);
    const std::string html = host::run::report_html(o->run, o->max_views);
    io::write_file_atomic(out, [&](std::ostream& s) { s << html; });
    std::cout << "report: " << out.string() << " (" << html.size() / 1024 << " KiB)\n";
  });
}

}  // namespace litgs::tools
