// The viewer page in headless Chromium (Debian `chromium`): it loads with no console error, a camera given in
// the URL gives a screenshot whose pixels are the model's render, and one navigation step changes the
// picture. Skipped, saying so, only where /usr/bin/chromium is absent (ci/setup installs it).
#include <unistd.h>

#include <cstdlib>
#include <filesystem>

#include "engine_cli.h"
#include "io/image.h"
#include "serve_fixture.h"

namespace litgs::testing {
namespace {

namespace fs = std::filesystem;

constexpr const char* kChromium = "/usr/bin/chromium";
// 160x128 looking down +z: the random scene fills it (fx = w for its field of view).
constexpr const char* kViewCamera = "q=1,0,0,0&t=0,0,0&fx=160&fy=160&cx=80&cy=64&w=160&h=128";
constexpr const char* kCliViewCamera =
    "--pose 1 0 0 0 0 0 0 --intrinsics 160 160 80 64 --width 160 --height 128";

class ViewerChromium : public ServeTest {
 protected:
  void SetUp() override {
    if (!fs::exists(kChromium)) GTEST_SKIP() << kChromium << " is not installed (ci/setup installs chromium)";
  }
  // Runs headless Chromium on the viewer with `query`; `mode` is --screenshot=FILE or --dump-dom. Returns
  // stdout + stderr (console messages are logged to stderr).
  std::string chromium(const std::string& query, const std::string& mode) {
    const fs::path profile = dir() / ("chromium-profile-" + std::to_string(runs_++));
    fs::remove_all(profile);
    const std::string url = "http://127.0.0.1:" + std::to_string(port()) + "/?" + query;
    const std::string cmd = std::string(kChromium) +
                            " --headless --no-sandbox --disable-gpu --disable-quic --no-first-run"
                            " --disable-background-networking --disable-component-update --disable-sync"
                            " --user-data-dir=" +
                            profile.string() +
                            " --window-size=900,400 --hide-scrollbars --force-device-scale-factor=1"
                            " --force-color-profile=srgb --enable-logging=stderr --v=0"
                            " --virtual-time-budget=30000 " +
                            mode + " '" + url + "' 2>&1";
    std::string out;
    FILE* pipe = popen(cmd.c_str(), "r");
    if (!pipe) return "popen failed";
    char buf[4096];
    while (fgets(buf, sizeof buf, pipe)) out += buf;
    pclose(pipe);
    fs::remove_all(profile);
    return out;
  }
  io::Image screenshot(const std::string& query, const char* name) {
    const std::string file = path(name);
    const std::string log = chromium(query, "--screenshot=" + file);
    EXPECT_TRUE(fs::exists(file)) << log;
    if (!fs::exists(file)) return {};
    EXPECT_EQ(log.find("CONSOLE"), std::string::npos) << "console output:\n" << log;
    return io::read_image(file);
  }
  int runs_ = 0;
};

// The render region of a screenshot (the canvas sits at the page's top-left corner) as gray values.
std::vector<int> canvas_region(const io::Image& shot, int w, int h) {
  std::vector<int> gray;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) gray.push_back(shot.at(x, y, 0));
  return gray;
}

TEST_F(ViewerChromium, PageLoadsWithoutConsoleErrorsAndRenders) {
  const std::string dom = chromium(std::string(kViewCamera) + "&palette=gray&range=0,1", "--dump-dom");
  EXPECT_NE(dom.find("data-frames=\"1\""), std::string::npos) << dom;
  EXPECT_NE(dom.find("<div id=\"errors\"></div>"), std::string::npos) << "the page reported errors:\n" << dom;
  EXPECT_EQ(dom.find("CONSOLE"), std::string::npos) << dom;
}

TEST_F(ViewerChromium, UrlCameraScreenshotShowsTheModelsRender) {
  const io::Image shot = screenshot(std::string(kViewCamera) + "&palette=gray&range=0,1", "view.png");
  ASSERT_GE(shot.width, 160);
  ASSERT_GE(shot.height, 128);
  // The same view from `litgs-engine render`, 8-bit: the gray palette over [0, 1] is the same rounding.
  const CommandResult r =
      run_engine("render --model " + model_path() + " " + kCliViewCamera + " --out " + path("cli-view.png"));
  ASSERT_EQ(r.status, 0) << r.output;
  const io::Image cli = io::read_image(path("cli-view.png"));
  const std::vector<int> seen = canvas_region(shot, 160, 128);
  size_t equal = 0, lit = 0;
  for (size_t i = 0; i < seen.size(); ++i) {
    equal += std::abs(seen[i] - int(cli.data[i])) <= 1;
    lit += seen[i] > 20;
  }
  EXPECT_GE(equal, seen.size() * 99 / 100) << "the screenshot's canvas is the model's render";
  EXPECT_GT(lit, seen.size() / 2) << "the model fills the view";
}

TEST_F(ViewerChromium, NavigationStepChangesThePicture) {
  const std::string base = std::string(kViewCamera) + "&palette=gray&range=0,1";
  const std::vector<int> before = canvas_region(screenshot(base, "before.png"), 160, 128);
  const std::vector<int> after = canvas_region(screenshot(base + "&nav=orbit:40,0", "after.png"), 160, 128);
  ASSERT_EQ(before.size(), after.size());
  size_t changed = 0;
  for (size_t i = 0; i < before.size(); ++i) changed += std::abs(before[i] - after[i]) > 8;
  EXPECT_GT(changed, before.size() / 10) << "an orbit step of 40 pixels moves the view";
  const std::vector<int> fly = canvas_region(screenshot(base + "&nav=move:0.5", "fly.png"), 160, 128);
  size_t moved = 0;
  for (size_t i = 0; i < before.size(); ++i) moved += std::abs(before[i] - fly[i]) > 8;
  EXPECT_GT(moved, before.size() / 10) << "half a metre forward changes the view";
}

// The text of the element with id `id` in a dumped DOM ("" if absent).
std::string element_text(const std::string& dom, const std::string& id) {
  const std::string open = "id=\"" + id + "\">";
  const size_t at = dom.find(open);
  if (at == std::string::npos) return "";
  const size_t start = at + open.size();
  return dom.substr(start, dom.find('<', start) - start);
}

TEST_F(ViewerChromium, LegendAndRangeAreInTheDataUnitsOfLevelsJson) {
  // models/counts/ holds a levels.json mapping intensity 0..1 to raw counts 1000..2000.
  const auto load =
      client()->Post("/models/load", R"({"name": "counts", "path": "counts/model.ply"})", "application/json");
  ASSERT_TRUE(load);
  ASSERT_EQ(load->status, 200) << load->body;
  const std::string dom = chromium(std::string(kViewCamera) + "&model=counts&palette=gray", "--dump-dom");
  EXPECT_NE(dom.find("data-frames=\"1\""), std::string::npos) << dom;
  EXPECT_EQ(element_text(dom, "legend-unit"), "intensity (raw counts)") << dom;
  const double lo = std::atof(element_text(dom, "legend-lo").c_str());
  const double hi = std::atof(element_text(dom, "legend-hi").c_str());
  EXPECT_GE(lo, 1000.0) << dom;  // the auto range of the render, in counts
  EXPECT_LE(hi, 2000.0) << dom;
  EXPECT_GT(hi, lo + 10.0) << dom;
  // The default model has no levels.json: model units.
  const std::string plain = chromium(std::string(kViewCamera) + "&palette=gray", "--dump-dom");
  EXPECT_EQ(element_text(plain, "legend-unit"), "intensity (model units)") << plain;
}

// With --scene, the viewer opens at the scene's first camera (not at an orbit outside the model's bounds,
// which saw a facade edge-on), lists every camera by its number and jumps to the one typed. The model is a
// training of one iteration from the scene's LiDAR map, so it stands where the cameras look.
class ViewerChromiumScene : public ViewerChromium {
 public:
  static void SetUpTestSuite() {
    scene_ = fs::temp_directory_path() / ("litgs-viewer-scene-" + std::to_string(::getpid()));
    fs::remove_all(scene_);
    const CommandResult synth =
        run_engine("synth --frames 12 --width 64 --height 48 --out " + (scene_ / "scene").string());
    ASSERT_EQ(synth.status, 0) << synth.output;
    const CommandResult train =
        run_engine("train " + (scene_ / "scene").string() + " --out " + (scene_ / "run").string() +
                   " --iterations 1 --max-gaussians 2000");
    ASSERT_EQ(train.status, 0) << train.output;
    extra_args_ = {"--scene", (scene_ / "scene").string()};
    ServeTest::SetUpTestSuite();
    fs::copy_file(scene_ / "run/point_cloud.ply", dir() / "models/facade.ply");
  }
  static void TearDownTestSuite() {
    ServeTest::TearDownTestSuite();
    fs::remove_all(scene_);
  }
  static inline fs::path scene_;
};

TEST_F(ViewerChromiumScene, OpensAtTheFirstCameraWithTheModelFillingTheViewAndJumpsByNumber) {
  const auto load =
      client()->Post("/models/load", R"({"name": "facade", "path": "facade.ply"})", "application/json");
  ASSERT_TRUE(load);
  ASSERT_EQ(load->status, 200) << load->body;
  const std::vector<int> first =
      canvas_region(screenshot("model=facade&palette=gray&range=0,1", "first.png"), 64, 48);
  size_t lit = 0;
  for (const int v : first) lit += v > 20;
  EXPECT_GT(lit, first.size() * 6 / 10) << "the first view shows the model across most of the canvas";
  // The same view as asking for camera 0 by number.
  const std::vector<int> camera0 =
      canvas_region(screenshot("model=facade&palette=gray&range=0,1&camera=0", "camera0.png"), 64, 48);
  EXPECT_EQ(first, camera0);
  const std::string dom = chromium("model=facade&palette=gray&range=0,1", "--dump-dom");
  EXPECT_EQ(element_text(dom, "camera-11").rfind("11: ", 0), 0u) << dom;  // two digits, not clipped
  EXPECT_NE(dom.find("id=\"camera-index\""), std::string::npos) << dom;
}

}  // namespace
}  // namespace litgs::testing
