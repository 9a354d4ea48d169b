#include "serve_fixture.h"

#include <signal.h>
#include <unistd.h>

#include <fstream>
#include <iterator>

#include "io/gaussian_ply.h"
#include "splat_scenes.h"

namespace litgs::testing {

namespace fs = std::filesystem;

void ServeTest::SetUpTestSuite() {
  dir_ = fs::temp_directory_path() /
         ("litgs-serve-" + std::string(::testing::UnitTest::GetInstance()->current_test_suite()->name()) +
          "-" + std::to_string(::getpid()));
  fs::remove_all(dir_);
  fs::create_directories(dir_ / "models");
  io::write_gaussian_ply(dir_ / "model.ply", random_scene(300, 1, 3, 5));
  io::write_gaussian_ply(dir_ / "models" / "other.ply", random_scene(200, 1, 1, 9));
  io::write_gaussian_ply(dir_ / "models" / "same.ply", random_scene(300, 1, 3, 5));
  io::write_gaussian_ply(dir_ / "outside.ply", random_scene(10, 1, 0, 1));
  // A model with train's levels.json beside it: its intensity 0..1 is raw counts 1000..2000.
  fs::create_directories(dir_ / "models" / "counts");
  io::write_gaussian_ply(dir_ / "models" / "counts" / "model.ply", random_scene(300, 1, 3, 5));
  // (written by hand: Eigen, which host/train/level_plan.h pulls in, clashes with httplib's resolv.h)
  std::ofstream(dir_ / "models" / "counts" / "levels.json")
      << R"({"level_model": "none", "stretch_low": 1000, "stretch_high": 2000, "vignetting_k1": 0,
             "vignetting_k2": 0, "frames": []})";
  fs::create_symlink(dir_ / "outside.ply", dir_ / "models" / "link.ply");
  std::ofstream(dir_ / "models" / "broken.ply") << "ply\nformat ascii 1.0\nend_header\n";
  std::vector<std::string> args = {"--model", model_path(), "--models-dir", path("models"),   "--max-pixels",
                                   "400000",  "--max-body", "65536",        "--read-timeout", "1"};
  args.insert(args.end(), extra_args_.begin(), extra_args_.end());
  server_ = std::make_unique<serve::ServerProcess>(LITGS_ENGINE_BINARY, args);
}

void ServeTest::TearDownTestSuite() {
  if (server_) {
    // The device saw no validation error during the suite (LITGS_VALIDATION=1 in ctest).
    auto c = client();
    if (const auto res = c->Get("/healthz"); res && res->status == 200) {
      const auto j = nlohmann::json::parse(res->body);
      if (j.contains("validation_errors")) {
        EXPECT_EQ(j["validation_errors"], 0) << res->body;
      }
    }
    EXPECT_EQ(server_->stop(SIGTERM), 0) << server_->output();
    server_.reset();
  }
  fs::remove_all(dir_);
  extra_args_.clear();
}

std::unique_ptr<httplib::Client> ServeTest::client() {
  auto c = std::make_unique<httplib::Client>("127.0.0.1", port());
  c->set_read_timeout(60, 0);
  c->set_connection_timeout(10, 0);
  return c;
}

std::string render_json(const std::string& outputs, const std::string& extra) {
  std::string body = R"({"pose": {"T_cam_world": {"q": [1, 0, 0, 0], "t": [0, 0, 0]}},
    "intrinsics": {"fx": 60, "fy": 60, "cx": 32, "cy": 24}, "width": 64, "height": 48)";
  if (!outputs.empty()) body += ", \"outputs\": " + outputs;
  if (!extra.empty()) body += ", " + extra;
  return body + "}";
}

nlohmann::json body_json(const httplib::Result& res) {
  if (!res) {
    ADD_FAILURE() << "no response: " << httplib::to_string(res.error());
    return nullptr;
  }
  try {
    return nlohmann::json::parse(res->body);
  } catch (const std::exception& e) {
    ADD_FAILURE() << "not JSON (" << e.what() << "): " << res->body.substr(0, 200);
    return nullptr;
  }
}

void expect_error(const httplib::Result& res, int status, const std::string& words) {
  ASSERT_TRUE(res) << "no response: " << httplib::to_string(res.error());
  EXPECT_EQ(res->status, status) << res->body;
  EXPECT_EQ(res->get_header_value("Content-Type"), "application/json");
  const nlohmann::json j = body_json(res);
  ASSERT_TRUE(j.is_object() && j.contains("error") && j["error"].is_string()) << res->body;
  EXPECT_NE(j["error"].get<std::string>().find(words), std::string::npos)
      << "expected '" << words << "' in: " << j["error"];
}

std::string file_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

std::string base64_decode(const std::string& text) {
  auto value = [](char c) -> int {
    if (c >= 'A' && c <= 'Z') return c - 'A';
    if (c >= 'a' && c <= 'z') return c - 'a' + 26;
    if (c >= '0' && c <= '9') return c - '0' + 52;
    return c == '+' ? 62 : c == '/' ? 63 : -1;
  };
  std::string out;
  uint32_t bits = 0;
  int count = 0;
  for (char c : text) {
    const int v = value(c);
    if (v < 0) continue;  // padding
    bits = bits << 6 | static_cast<uint32_t>(v);
    count += 6;
    if (count >= 8) {
      count -= 8;
      out += static_cast<char>((bits >> count) & 0xff);
    }
  }
  return out;
}

}  // namespace litgs::testing
