// DIR/report.html in headless Chromium (Debian's chromium): the page runs without console messages, draws its
// four charts (the fourth: the trajectories' top view), and the screenshot's pixels show the charts (their
// line colours in the chart band) and the pictures (false-colour and gray pixels in the views band). Controls
// show each check can fail: a page with a script error is caught, and the report without its charts has no
// chart pixels. A run whose budget grew inside the training draws the two growth charts as well.
#include <gtest/gtest.h>
#include <unistd.h>

#include <array>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <nlohmann/json.hpp>
#include <sstream>

#include "io/image.h"
#include "run_test_support.h"

namespace litgs::testing {
namespace {

namespace fs = std::filesystem;

const fs::path kRoot = LITGS_RUN_TEST_DIR;

struct Browser {
  std::string out, err;
  int status;
};

std::string slurp(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// One headless Chromium call on a local page, with a fresh profile; `mode` is --dump-dom or
// --screenshot=FILE. Its console messages come out on stderr as "...:CONSOLE:LINE] ...".
Browser chromium(const fs::path& page, const std::string& mode, const std::string& extra = "") {
  static int call = 0;
  const fs::path profile =
      kRoot / ("chromium-profile-" + std::to_string(::getpid()) + "-" + std::to_string(call++));
  fs::remove_all(profile);
  const fs::path out = profile.string() + ".out", err = profile.string() + ".err";
  const std::string cmd =
      "timeout 120 /usr/bin/chromium --headless --no-sandbox --disable-gpu --disable-quic --no-first-run "
      "--disable-background-networking --disable-component-update --disable-sync --hide-scrollbars "
      "--enable-logging=stderr --v=0 --window-size=1280,1200 --user-data-dir=" +
      profile.string() + " " + extra + " " + mode + " file://" + fs::absolute(page).string() + " > " +
      out.string() + " 2> " + err.string();
  Browser b;
  b.status = std::system(cmd.c_str());
  b.out = slurp(out);
  b.err = slurp(err);
  fs::remove_all(profile);
  return b;
}

std::vector<std::string> console_lines(const std::string& err) {
  std::vector<std::string> lines;
  std::istringstream in(err);
  for (std::string line; std::getline(in, line);)
    if (line.find(":CONSOLE") != std::string::npos) lines.push_back(line);
  return lines;
}

// Pixels of the screenshot rows [y0, y1) whose colour is within `tolerance` of `rgb` in every channel.
size_t count_colour(const io::Image& img, int y0, int y1, std::array<int, 3> rgb, int tolerance = 24) {
  size_t n = 0;
  for (int y = y0; y < std::min(y1, img.height); ++y)
    for (int x = 0; x < img.width; ++x) {
      bool close = true;
      for (int c = 0; c < 3; ++c) close = close && std::abs(int{img.at(x, y, c)} - rgb[c]) <= tolerance;
      n += close;
    }
  return n;
}

// Strongly coloured pixels (max - min channel above 90) and mid-gray ones (channels within 6, 40..215).
std::pair<size_t, size_t> colour_and_gray(const io::Image& img, int y0, int y1) {
  size_t colour = 0, gray = 0;
  for (int y = y0; y < std::min(y1, img.height); ++y)
    for (int x = 0; x < img.width; ++x) {
      const int r = img.at(x, y, 0), g = img.at(x, y, 1), b = img.at(x, y, 2);
      const int hi = std::max({r, g, b}), lo = std::min({r, g, b});
      colour += hi - lo > 90;
      gray += hi - lo <= 6 && lo >= 40 && hi <= 215;
    }
  return {colour, gray};
}

class RunReport : public ::testing::Test {
 protected:
  void SetUp() override {
    report_ = kRoot / "e2e" / "report.html";
    ASSERT_TRUE(fs::exists(report_)) << report_
                                     << " is missing: RunPipeline.SyntheticEndToEnd* makes it (ctest "
                                     << "runs it first as this test's fixture)";
    ASSERT_TRUE(fs::exists("/usr/bin/chromium")) << "install chromium (ci/setup)";
  }
  // A copy of the end-to-end run's folder as `name` (the run's metrics, evaluation and, unless
  // `with_trace`, an empty trace), whose metrics.json `edit` changes.
  fs::path copy_run(const char* name, bool with_trace, const std::function<void(nlohmann::json&)>& edit) {
    const fs::path dir = kRoot / name;
    fs::remove_all(dir);
    fs::create_directories(dir / "train");
    for (const char* part : {"run.json", "train/metrics.json", "train/trace.jsonl"})
      fs::copy_file(report_.parent_path() / part, dir / part);
    if (!with_trace) write_text(dir / "train/trace.jsonl", "");
    fs::copy(report_.parent_path() / "eval", dir / "eval", fs::copy_options::recursive);
    nlohmann::json metrics = nlohmann::json::parse(slurp(dir / "train/metrics.json"));
    edit(metrics);
    write_text(dir / "train/metrics.json", metrics.dump());
    return dir;
  }
  // `litgs-engine report` on `dir`, then its page in Chromium: the DOM, and no console message.
  static Browser report_in_chromium(const fs::path& dir) {
    const std::string cmd = std::string(LITGS_ENGINE_BINARY) + " report --run " + dir.string() + " > " +
                            (dir / "report.log").string() + " 2>&1";
    EXPECT_EQ(std::system(cmd.c_str()), 0) << slurp(dir / "report.log");
    const Browser b = chromium(dir / "report.html", "--dump-dom");
    EXPECT_EQ(b.status, 0) << b.err;
    EXPECT_EQ(console_lines(b.err), std::vector<std::string>{})
        << "console messages while loading the report";
    return b;
  }
  fs::path report_;
};

TEST_F(RunReport, LoadsWithoutConsoleMessagesAndDrawsItsCharts) {
  const Browser b = chromium(report_, "--dump-dom");
  ASSERT_EQ(b.status, 0) << b.err;
  EXPECT_EQ(console_lines(b.err), std::vector<std::string>{}) << "console messages while loading the report";
  EXPECT_NE(b.out.find("data-charts=\"5\""), std::string::npos)
      << "the chart script did not finish (or drew no trajectories)";
  // Self-contained: no address outside the file.
  const std::string html = slurp(report_);
  EXPECT_EQ(html.find("src=\"http"), std::string::npos);
  EXPECT_EQ(html.find("href=\"http"), std::string::npos);

  // Control: a script error in a page is seen by this check.
  const fs::path bad =
      write_text(kRoot / "bad-page.html", "<html><body><script>notAFunction();</script></body></html>");
  const Browser c = chromium(bad, "--dump-dom");
  ASSERT_EQ(console_lines(c.err).size(), 1u) << c.err;
  EXPECT_NE(console_lines(c.err)[0].find("Uncaught ReferenceError"), std::string::npos);
}

// The same run as if its budget had grown inside the training (metrics.json's budget_growth, as
// BudgetGrowth::to_json writes it): the Budget section's two growth charts are drawn too.
TEST_F(RunReport, AGrownBudgetDrawsItsTwoGrowthCharts) {
  const fs::path grown = copy_run("e2e-grown", true, [](nlohmann::json& metrics) {
    metrics["budget_growth"] = nlohmann::json::parse(R"json({"budget": 20000, "ceiling": 8000000,
      "stop_reason": "stop: validation gained 0.010 dB", "last_scored_view_psnr_db": [],
      "last_scored_training_psnr_db": [], "phases": [
      {"iteration": 600, "budget": 5000, "gaussians": 5000, "validation_psnr_db": 30.1, "gain_db": null,
       "gain_se_db": null, "training_psnr_db": 31.0, "training_gain_db": null, "wall_s": 10.0,
       "decision": "grow: first score; budget 10000"},
      {"iteration": 900, "budget": 10000, "gaussians": 10000, "validation_psnr_db": 30.9, "gain_db": 0.8,
       "gain_se_db": 0.1, "training_psnr_db": 32.0, "training_gain_db": 1.0, "wall_s": 16.0,
       "decision": "grow: validation gained 0.800 dB; budget 20000"},
      {"iteration": 1200, "budget": 20000, "gaussians": 20000, "validation_psnr_db": 30.91, "gain_db": 0.01,
       "gain_se_db": 0.1, "training_psnr_db": 32.5, "training_gain_db": 0.5, "wall_s": 25.0,
       "decision": "stop: validation gained 0.010 dB"}]})json");
  });
  const Browser b = report_in_chromium(grown);
  EXPECT_NE(b.out.find("data-charts=\"7\""), std::string::npos)
      << "the growth charts were not drawn beside the five of the run";
  EXPECT_NE(b.out.find("Grown inside the training"), std::string::npos);
}

// The same run as if trained in two blocks (metrics.json's blocks, each with its own trace; the top-level
// trace empty, as train_in_blocks writes them): the charts draw each block's curves.
TEST_F(RunReport, ATrainingInBlocksDrawsEachBlocksCurves) {
  const fs::path blocks = copy_run("e2e-blocks", false, [](nlohmann::json& metrics) {
    metrics["blocks"] = nlohmann::json::array();
    for (const char* name : {"block-0-0", "block-1-0"})
      metrics["blocks"].push_back(
          {{"name", name}, {"trace", std::string("partition/blocks/") + name + "/train/trace.jsonl"}});
  });
  const nlohmann::json metrics = nlohmann::json::parse(slurp(blocks / "train/metrics.json"));
  for (const auto& block : metrics["blocks"]) {
    const fs::path trace = blocks / "train" / block["trace"].get<std::string>();
    fs::create_directories(trace.parent_path());
    fs::copy_file(report_.parent_path() / "train/trace.jsonl", trace);
  }
  const Browser b = report_in_chromium(blocks);
  EXPECT_NE(b.out.find("data-charts=\"5\""), std::string::npos) << "the chart script did not finish";
  EXPECT_NE(slurp(blocks / "report.html").find("\"name\":\"block-1-0\""), std::string::npos);
}

TEST_F(RunReport, ScreenshotShowsChartsAndPictures) {
  // Layout (report_html.cc's style, CSS pixels = screenshot pixels): the charts in rows 40..340, the
  // held-out views from about 380 on, 196 rows each.
  const fs::path shot = kRoot / "report-shot.png";
  fs::remove(shot);
  const Browser b = chromium(report_, "--screenshot=" + shot.string());
  ASSERT_EQ(b.status, 0) << b.err;
  const io::Image img = io::read_image(shot);
  ASSERT_GE(img.channels, 3);
  ASSERT_EQ(img.width, 1280);
  const std::array<int, 3> red = {0xd6, 0x27, 0x28}, blue = {0x1f, 0x77, 0xb4}, green = {0x2c, 0xa0, 0x2c};
  // Each curve and its legend box: a few hundred pixels at least (a legend box alone is 40x12).
  EXPECT_GT(count_colour(img, 40, 340, red), 600u);
  EXPECT_GT(count_colour(img, 40, 340, blue), 600u);
  EXPECT_GT(count_colour(img, 40, 340, green), 600u);
  // The trajectories' top view (the fourth chart, x >= 900): truth drawn 6 px wide under the refined poses
  // (2 px), so both show; the prior mostly lies under them at this scale (millimetres of ATE on a metres
  // wide chart): its legend box (40x12) at least.
  const auto in_trajectory_chart = [&](std::array<int, 3> rgb) {
    size_t n = 0;
    for (int y = 40; y < 340; ++y)
      for (int x = 900; x < img.width; ++x) {
        bool close = true;
        for (int c = 0; c < 3; ++c) close = close && std::abs(int{img.at(x, y, c)} - rgb[c]) <= 24;
        n += close;
      }
    return n;
  };
  const std::array<int, 3> purple = {0x94, 0x67, 0xbd}, orange = {0xff, 0x7f, 0x0e},
                           cyan = {0x17, 0xbe, 0xcf};
  EXPECT_GT(in_trajectory_chart(purple), 600u) << "truth trajectory missing";
  EXPECT_GT(in_trajectory_chart(cyan), 600u) << "refined trajectory missing";
  EXPECT_GT(in_trajectory_chart(orange), 300u) << "prior trajectory's legend missing";
  // The pictures: five 160-row images per view; the error, false-colour and depth pictures are strongly
  // coloured, the render and the frame gray.
  const auto [colour, gray] = colour_and_gray(img, 380, 380 + 196);
  EXPECT_GT(colour, 3u * 160 * 100) << "false-colour pictures missing";
  EXPECT_GT(gray, 160u * 100) << "gray pictures missing";

  // Control: the same report with the charts' construction taken out has no chart pixels (the check sees
  // the charts, not the rest of the page).
  std::string html = slurp(report_);
  size_t replaced = 0;
  for (size_t at = 0; (at = html.find("new Chart(document", at)) != std::string::npos; ++replaced)
    html.replace(at, 10, "void(");
  ASSERT_EQ(replaced, 2u);  // the three curves' charts through one function, and the trajectories
  const fs::path without = write_text(kRoot / "report-without-charts.html", html);
  const fs::path off = kRoot / "report-shot-without-charts.png";
  fs::remove(off);
  ASSERT_EQ(chromium(without, "--screenshot=" + off.string()).status, 0);
  const io::Image no_charts = io::read_image(off);
  EXPECT_LT(count_colour(no_charts, 40, 340, red) + count_colour(no_charts, 40, 340, blue), 50u);
  EXPECT_LT(count_colour(no_charts, 40, 340, purple) + count_colour(no_charts, 40, 340, cyan), 50u);
}

}  // namespace
}  // namespace litgs::testing
