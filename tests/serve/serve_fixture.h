// The HTTP tests' fixture: one `litgs-engine serve` process per test suite on an ephemeral loopback port,
// serving a small random model (300 Gaussians, SH degree 3, one channel) with --models-dir holding a second
// model, a symlink out and a file outside; and helpers to call it.
#pragma once

#include <gtest/gtest.h>
#include <httplib.h>

#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "engine_cli.h"
#include "tools/serve/server_process.h"

namespace litgs::testing {

class ServeTest : public ::testing::Test {
 public:
  static void SetUpTestSuite();
  static void TearDownTestSuite();  // SIGTERM: the server must exit 0

 protected:
  static std::unique_ptr<httplib::Client> client();
  static int port() { return server_->port(); }
  static const std::filesystem::path& dir() { return dir_; }
  static std::string path(const char* name) { return (dir_ / name).string(); }
  static std::string model_path() { return path("model.ply"); }
  // Extra server options for a suite (a subclass's SetUpTestSuite sets them before calling ours).
  static inline std::vector<std::string> extra_args_;
  static inline std::unique_ptr<serve::ServerProcess> server_;
  static inline std::filesystem::path dir_;
};

// The camera the tests render: 64x48, looking down +z at the random scene, as `render` flags and as JSON.
inline constexpr const char* kCliCamera =
    "--pose 1 0 0 0 0 0 0 --intrinsics 60 60 32 24 --width 64 --height 48";
std::string render_json(const std::string& outputs = "", const std::string& extra = "");
inline constexpr const char* kQueryCamera =
    "pose=T_cam_world&q=1,0,0,0&t=0,0,0&fx=60&fy=60&cx=32&cy=24&width=64&height=48";

// The body as JSON, with a failure (and null) if it is not.
nlohmann::json body_json(const httplib::Result& res);
// Expects status `status` and a JSON {"error": ...} whose message contains `words`.
void expect_error(const httplib::Result& res, int status, const std::string& words);
// Bytes of a file.
std::string file_bytes(const std::string& path);
std::string base64_decode(const std::string& text);

}  // namespace litgs::testing
