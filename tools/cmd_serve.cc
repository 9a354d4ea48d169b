// `litgs-engine serve`: the headless render service (tools/serve/, docs/serve.md).
#include <CLI/CLI.hpp>
#include <memory>

#include "tools/commands.h"
#include "tools/serve/http_server.h"

namespace litgs::tools {

void add_serve_command(CLI::App& app) {
  auto o = std::make_shared<serve::ServeOptions>();
  CLI::App* cmd =
      app.add_subcommand("serve", "Render service over HTTP with a browser viewer (docs/serve.md)");
  cmd->add_option("--model", o->model, "3DGS PLY model, served as 'default'")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("--scene", o->scene, "Scene directory: poses in its frame, its cameras in GET /model")
      ->check(CLI::ExistingDirectory);
  cmd->add_option("--levels", o->levels,
                  "train's levels.json: legends in the data's units (default: levels.json beside --model)")
      ->check(CLI::ExistingFile);
  cmd->add_option("--host", o->host, "Address to bind (loopback by default)")->capture_default_str();
  cmd->add_option("--port", o->port, "TCP port (0: any free port, printed)")->capture_default_str();
  cmd->add_option("--max-queue", o->max_queue, "Renders waiting for the device before 503")
      ->capture_default_str();
  cmd->add_option("--max-pixels", o->max_pixels, "Largest width x height of a render")->capture_default_str();
  cmd->add_option("--models-dir", o->models_dir,
                  "Folder POST /models/load may read from (default: loading off)");
  cmd->add_option("--request-timeout", o->request_timeout_s, "Seconds before an unfinished render gets 503")
      ->capture_default_str();
  cmd->add_option("--max-body", o->max_body_bytes, "Largest request body in bytes (413 above)")
      ->capture_default_str();
  cmd->add_option("--read-timeout", o->read_timeout_s, "Seconds a silent client keeps its connection")
      ->capture_default_str();
  cmd->add_option("--threads", o->threads, "HTTP threads (0: max-queue + 4)")->capture_default_str();
  cmd->callback([o] { serve::run_http_server(*o); });
}

}  // namespace litgs::tools
