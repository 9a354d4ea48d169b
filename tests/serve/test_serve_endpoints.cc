// Every endpoint of `litgs-engine serve` against a real server: renders equal `litgs-engine render` of the
// same view bit for bit, the model and its reload, metrics, health, the viewer's files.
#include <signal.h>

#include <cmath>
#include <cstring>
#include <fstream>
#include <thread>

#include "io/image.h"
#include "io/palette.h"
#include "serve_fixture.h"

namespace litgs::testing {
namespace {

using nlohmann::json;

// `litgs-engine render` of the test camera: the PNG bytes of image (bit depth), depth and alpha.
struct CliRender {
  std::string image, depth, alpha;
};
CliRender cli_render(const std::string& model, int bit_depth) {
  const std::string out = "/tmp/litgs-serve-cli-" + std::to_string(::getpid());
  const CommandResult r =
      run_engine("render --model " + model + " " + kCliCamera + " --bit-depth " + std::to_string(bit_depth) +
                 " --out " + out + "-image.png --depth " + out + "-depth.png --alpha " + out + "-alpha.png");
  EXPECT_EQ(r.status, 0) << r.output;
  CliRender c{file_bytes(out + "-image.png"), file_bytes(out + "-depth.png"), file_bytes(out + "-alpha.png")};
  for (const char* k : {"-image.png", "-depth.png", "-alpha.png"}) std::filesystem::remove(out + k);
  return c;
}

TEST_F(ServeTest, HealthzSaysOk) {
  const auto res = client()->Get("/healthz");
  ASSERT_TRUE(res);
  EXPECT_EQ(res->status, 200);
  const json j = body_json(res);
  EXPECT_EQ(j["status"], "ok");
  EXPECT_GE(j["models"].get<int>(), 1);
}

TEST_F(ServeTest, RenderPngEqualsTheCommandLineBitForBit) {
  const CliRender cli = cli_render(model_path(), 8);
  ASSERT_GT(cli.image.size(), 100u);
  const auto post = client()->Post("/render", render_json(), "application/json");
  ASSERT_TRUE(post);
  ASSERT_EQ(post->status, 200) << post->body;
  EXPECT_EQ(post->get_header_value("Content-Type"), "image/png");
  EXPECT_EQ(post->body, cli.image);
  EXPECT_EQ(post->get_header_value("X-Model-Version").rfind("default@", 0), 0u);
  EXPECT_GE(std::stod(post->get_header_value("X-Render-Ms")),
            std::stod(post->get_header_value("X-Device-Ms")));
  const auto get = client()->Get(std::string("/render?") + kQueryCamera);
  ASSERT_TRUE(get);
  ASSERT_EQ(get->status, 200) << get->body;
  EXPECT_EQ(get->body, cli.image);
}

TEST_F(ServeTest, BundleOf16BitImageDepthAndAlphaEqualsTheCommandLine) {
  const CliRender cli = cli_render(model_path(), 16);
  const auto res = client()->Post(
      "/render", render_json(R"({"image": {"format": "png16"}, "depth": {"format": "png16", "scale": 1000},
                      "alpha": {"format": "png8"}})"),
      "application/json");
  ASSERT_TRUE(res);
  ASSERT_EQ(res->status, 200) << res->body;
  const json j = body_json(res);
  EXPECT_EQ(j["width"], 64);
  EXPECT_EQ(base64_decode(j["outputs"]["image"]["base64"]), cli.image);
  EXPECT_EQ(base64_decode(j["outputs"]["depth"]["base64"]), cli.depth);
  EXPECT_EQ(base64_decode(j["outputs"]["alpha"]["base64"]), cli.alpha);
  EXPECT_EQ(j["outputs"]["depth"]["scale"], 1000.0);
}

TEST_F(ServeTest, Float32AndPaletteOutputsAgreeWithThePng) {
  const auto raw =
      client()->Post("/render", render_json(R"({"image": {"format": "float32"}})"), "application/json");
  ASSERT_TRUE(raw);
  ASSERT_EQ(raw->status, 200) << raw->body;
  EXPECT_EQ(raw->get_header_value("Content-Type"), "application/octet-stream");
  ASSERT_EQ(raw->body.size(), 64u * 48 * 4);
  std::vector<float> values(64 * 48);
  std::memcpy(values.data(), raw->body.data(), raw->body.size());
  const auto pal =
      client()->Post("/render", render_json(R"({"image": {"palette": "ironbow", "range": [0.1, 0.9]}})"),
                     "application/json");
  ASSERT_TRUE(pal);
  ASSERT_EQ(pal->status, 200) << pal->body;
  const std::string png_path = path("palette.png");
  std::ofstream(png_path, std::ios::binary) << pal->body;
  const io::Image rgb = io::read_image(png_path);
  ASSERT_EQ(rgb.channels, 3);
  size_t lit = 0;
  for (int p = 0; p < 64 * 48; ++p) {
    const io::Rgb want = io::palette_table(io::Palette::kIronbow)[io::palette_index(values[p], 0.1, 0.9)];
    for (int k = 0; k < 3; ++k) ASSERT_EQ(rgb.data[3 * p + k], want[k]) << "pixel " << p;
    lit += values[p] > 0.1f;
  }
  EXPECT_GT(lit, 64u * 48 / 2) << "the model fills the view";
}

TEST_F(ServeTest, CameraToWorldPoseRendersTheSameView) {
  // The test camera turned 90 degrees about z, given both ways.
  const double h = std::sqrt(0.5);
  const auto body = [](const char* direction, const json& q, const json& t) {
    return json{{"pose", {{direction, {{"q", q}, {"t", t}}}}},
                {"intrinsics", {{"fx", 60}, {"fy", 60}, {"cx", 32}, {"cy", 24}}},
                {"width", 64},
                {"height", 48},
                {"outputs", {{"image", {{"format", "float32"}}}}}}
        .dump();
  };
  const auto a =
      client()->Post("/render", body("T_cam_world", {h, 0, 0, h}, {0.1, 0, 0}), "application/json");
  // T_world_cam = inverse: R^T, -R^T t; R^T t for a 90 degree turn of (0.1, 0, 0) is (0, -0.1, 0).
  const auto b =
      client()->Post("/render", body("T_world_cam", {h, 0, 0, -h}, {0, 0.1, 0}), "application/json");
  ASSERT_TRUE(a && b);
  ASSERT_EQ(a->status, 200) << a->body;
  ASSERT_EQ(b->status, 200) << b->body;
  ASSERT_EQ(a->body.size(), b->body.size());
  std::vector<float> va(64 * 48), vb(64 * 48);
  std::memcpy(va.data(), a->body.data(), a->body.size());
  std::memcpy(vb.data(), b->body.data(), b->body.size());
  for (size_t i = 0; i < va.size(); ++i) ASSERT_NEAR(va[i], vb[i], 1e-4) << "pixel " << i;
}

TEST_F(ServeTest, ModelDescribesTheLoadedModel) {
  const auto res = client()->Get("/model");
  ASSERT_TRUE(res);
  ASSERT_EQ(res->status, 200) << res->body;
  const json j = body_json(res);
  EXPECT_EQ(j["name"], "default");
  EXPECT_EQ(j["gaussians"], 300);
  EXPECT_EQ(j["channels"], 1);
  EXPECT_EQ(j["sh_degree"], 3);
  EXPECT_EQ(j["pose_frame"], "model");
  EXPECT_TRUE(j["scene"].is_null());
  EXPECT_GT(j["device_bytes"].get<double>(), 300 * 4 * 14);
  for (int a = 0; a < 3; ++a)
    EXPECT_LT(j["bounds"]["min"][a].get<double>(), j["bounds"]["max"][a].get<double>());
  EXPECT_GE(j["bounds"]["min"][2].get<double>(), 1.5);  // random_scene's depths are 1.5 - 6 m
  EXPECT_LE(j["bounds"]["max"][2].get<double>(), 6.0);
  const auto list = client()->Get("/models");
  ASSERT_TRUE(list);
  EXPECT_EQ(list->status, 200);
  EXPECT_GE(body_json(list)["models"].size(), 1u);
}

TEST_F(ServeTest, MetricsAreInPrometheusTextFormat) {
  ASSERT_TRUE(client()->Post("/render", render_json(), "application/json"));
  const auto res = client()->Get("/metrics");
  ASSERT_TRUE(res);
  ASSERT_EQ(res->status, 200);
  EXPECT_EQ(res->get_header_value("Content-Type").rfind("text/plain", 0), 0u);
  for (const char* line :
       {"# TYPE litgs_http_requests_total counter",
        "litgs_http_requests_total{endpoint=\"/render\",status=\"200\"}",
        "# TYPE litgs_render_latency_seconds histogram", "litgs_render_latency_seconds_bucket{le=\"+Inf\"}",
        "litgs_render_device_seconds_count", "litgs_queue_depth 0", "litgs_renders_in_flight 0",
        "litgs_model_gaussians{model=\"default\"}", "process_resident_memory_bytes"})
    EXPECT_NE(res->body.find(line), std::string::npos) << line << "\n" << res->body;
}

TEST_F(ServeTest, ViewerPageAndScriptAreServed) {
  const auto page = client()->Get("/");
  ASSERT_TRUE(page);
  EXPECT_EQ(page->status, 200);
  EXPECT_EQ(page->get_header_value("Content-Type").rfind("text/html", 0), 0u);
  EXPECT_NE(page->body.find("<canvas id=\"view\""), std::string::npos);
  const auto script = client()->Get("/viewer.js");
  ASSERT_TRUE(script);
  EXPECT_EQ(script->status, 200);
  EXPECT_NE(script->body.find("/render"), std::string::npos);
  const auto palettes = client()->Get("/palettes");
  ASSERT_TRUE(palettes);
  const json p = body_json(palettes);
  EXPECT_EQ(p["gray"].size(), 256u);
  EXPECT_EQ(p["ironbow"].size(), 256u);
}

TEST_F(ServeTest, LoadSwapsTheModelAndBumpsItsVersion) {
  const auto load =
      client()->Post("/models/load", R"({"name": "second", "path": "other.ply"})", "application/json");
  ASSERT_TRUE(load);
  ASSERT_EQ(load->status, 200) << load->body;
  EXPECT_EQ(body_json(load)["gaussians"], 200);
  EXPECT_EQ(body_json(load)["version"], 1);
  const auto res =
      client()->Post("/render", render_json("", R"("model": "second", "sh_degree": 1)"), "application/json");
  ASSERT_TRUE(res);
  ASSERT_EQ(res->status, 200) << res->body;
  EXPECT_EQ(res->get_header_value("X-Model-Version"), "second@1");
  const CliRender cli = cli_render(path("models/other.ply"), 8);
  EXPECT_EQ(res->body, cli.image);
  const auto again =
      client()->Post("/models/load", R"({"name": "second", "path": "other.ply"})", "application/json");
  ASSERT_TRUE(again);
  EXPECT_EQ(body_json(again)["version"], 2);
}

// SIGINT and SIGTERM finish the renders in flight and exit 0.
TEST_F(ServeTest, SignalsFinishInFlightRequestsAndExitZero) {
  for (const int sig : {SIGTERM, SIGINT}) {
    serve::ServerProcess server(LITGS_ENGINE_BINARY, {"--model", model_path()});
    httplib::Client c("127.0.0.1", server.port());
    c.set_read_timeout(60, 0);
    int status = 0;
    std::string error;
    std::thread request([&] {
      const auto big = c.Post("/render", R"({"pose": {"T_cam_world": {"q": [1, 0, 0, 0], "t": [0, 0, 0]}},
        "intrinsics": {"fov_y_deg": 60}, "width": 2048, "height": 1536})",
                              "application/json");
      status = big ? big->status : -1;
      if (!big) error = httplib::to_string(big.error());
    });
    // Signal only once the server holds the request (a fixed sleep lost that race on a loaded machine).
    httplib::Client probe("127.0.0.1", server.port());
    bool in_flight = false;
    for (int i = 0; i < 600 && !in_flight; ++i) {
      const auto m = probe.Get("/metrics");
      in_flight = m && m->body.find("litgs_renders_in_flight 1") != std::string::npos;
      if (!in_flight) std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
    ASSERT_TRUE(in_flight) << "the render never reached the server\n" << server.output();
    EXPECT_EQ(server.stop(sig), 0) << server.output();
    request.join();
    EXPECT_EQ(status, 200) << error << "\n" << server.output();
    EXPECT_NE(server.output().find("serve: stopped (signal)"), std::string::npos) << server.output();
  }
}

// With --scene: the scene's cameras in GET /model, their real frames, poses in the scene's frame.
class ServeScene : public ServeTest {
 public:
  static void SetUpTestSuite() {
    scene_ = std::filesystem::temp_directory_path() / ("litgs-serve-scene-" + std::to_string(::getpid()));
    std::filesystem::remove_all(scene_);
    const CommandResult r = run_engine("synth --frames 6 --width 64 --height 48 --out " + scene_.string());
    ASSERT_EQ(r.status, 0) << r.output;
    extra_args_ = {"--scene", scene_.string()};
    ServeTest::SetUpTestSuite();
  }
  static void TearDownTestSuite() {
    ServeTest::TearDownTestSuite();
    std::filesystem::remove_all(scene_);
  }
  static inline std::filesystem::path scene_;
};

TEST_F(ServeScene, ModelListsTheScenesCamerasWithTheirFrames) {
  const auto res = client()->Get("/model");
  ASSERT_TRUE(res);
  ASSERT_EQ(res->status, 200) << res->body;
  const json j = body_json(res);
  EXPECT_EQ(j["pose_frame"], "scene");
  const json& cameras = j["scene"]["cameras"];
  ASSERT_EQ(cameras.size(), 6u) << j.dump();
  for (const json& c : cameras) {
    EXPECT_EQ(c["width"], 64);
    EXPECT_GT(c["intrinsics"]["fx"].get<double>(), 0);
    const json& q = c["pose"]["T_cam_world"]["q"];
    double norm = 0;
    for (const json& v : q) norm += v.get<double>() * v.get<double>();
    EXPECT_NEAR(norm, 1.0, 1e-9);
  }
  // The real frame beside a camera, and a render from its pose, as the viewer asks for them.
  const auto frame = client()->Get(cameras[2]["frame_url"].get<std::string>().c_str());
  ASSERT_TRUE(frame);
  ASSERT_EQ(frame->status, 200) << frame->body;
  EXPECT_EQ(frame->get_header_value("Content-Type"), "image/png");
  std::ofstream(path("frame.png"), std::ios::binary) << frame->body;
  const io::Image image = io::read_image(path("frame.png"));
  EXPECT_EQ(image.width, 64);
  EXPECT_EQ(image.bit_depth, 8);
  const json body = {
      {"pose", cameras[2]["pose"]}, {"intrinsics", cameras[2]["intrinsics"]}, {"width", 64}, {"height", 48}};
  const auto render = client()->Post("/render", body.dump(), "application/json");
  ASSERT_TRUE(render);
  EXPECT_EQ(render->status, 200) << render->body;
  expect_error(client()->Get("/scene/frames/99.png"), 404, "no scene frame 99");
}

}  // namespace
}  // namespace litgs::testing
