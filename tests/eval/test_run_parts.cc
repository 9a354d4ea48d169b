// The pipeline's parts that need no device: run.yaml, content hashes, INPUT kinds, the report's trace curve
// and base64; the ablation's base configuration.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

#include "host/run/ablate.h"
#include "host/run/content_hash.h"
#include "host/run/input_kind.h"
#include "host/run/report_budget.h"
#include "host/run/report_growth.h"
#include "host/run/report_html.h"
#include "host/run/run_config.h"
#include "io/error.h"

namespace litgs::host::run {
namespace {

namespace fs = std::filesystem;

class RunParts : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("litgs-run-parts-" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path write(const std::string& name, const std::string& text) {
    const fs::path p = dir_ / name;
    fs::create_directories(p.parent_path());
    std::ofstream(p) << text;
    return p;
  }
  std::string error_of(const fs::path& config) {
    try {
      read_run_config(config);
    } catch (const io::IoError& e) {
      return e.what();
    }
    return "";
  }
  fs::path dir_;
};

TEST_F(RunParts, PrintedDefaultsReadBackAsTheDefaults) {
  const RunConfig defaults;
  const fs::path p = write("run.yaml", run_config_yaml(defaults));
  EXPECT_EQ(to_json(read_run_config(p)), to_json(defaults));
  // And a changed value of each type survives the round trip.
  RunConfig c;
  c.train.iterations = 123;
  c.train.downscale = 2.5;
  c.train.strategy = "adc";
  c.eval.geometry = false;
  c.train.extra_args = {"--sh-degree", "1"};
  EXPECT_EQ(to_json(read_run_config(write("changed.yaml", run_config_yaml(c)))), to_json(c));
}

TEST_F(RunParts, ConfigKeysMayBeLeftOut) {
  const RunConfig c = read_run_config(write("partial.yaml", "train:\n  iterations: 50\n"));
  EXPECT_EQ(c.train.iterations, 50u);
  EXPECT_EQ(c.train.strategy, RunConfig().train.strategy);
  EXPECT_EQ(to_json(read_run_config(write("empty.yaml", ""))), to_json(RunConfig()));
}

// ablate starts from run's defaults with a fixed budget (a budget grown per variant would move with the
// studied option); keys its run.yaml leaves out keep that base, keys it gives override it.
TEST_F(RunParts, AblationBaseFixesTheBudgetThatRunGrows) {
  EXPECT_EQ(RunConfig().train.max_gaussians, "grow");
  const RunConfig base = ablation_base_config();
  EXPECT_EQ(base.train.max_gaussians, "40000");
  const RunConfig partial = read_run_config(write("ablate-partial.yaml", "train:\n  iterations: 50\n"), base);
  EXPECT_EQ(partial.train.max_gaussians, "40000");
  EXPECT_EQ(partial.train.iterations, 50u);
  const RunConfig given =
      read_run_config(write("ablate-budget.yaml", "train:\n  max_gaussians: 5000\n"), base);
  EXPECT_EQ(given.train.max_gaussians, "5000");
  EXPECT_EQ(to_json(read_run_config(write("ablate-empty.yaml", ""), base)), to_json(base));
}

TEST_F(RunParts, UnknownKeysAndBadValuesAreErrorsNamingThem) {
  std::string e = error_of(write("a.yaml", "train:\n  iterations: 5\n  iteratons: 7\n"));
  EXPECT_NE(e.find("unknown key 'train.iteratons'"), std::string::npos) << e;
  EXPECT_NE(e.find("a.yaml:3"), std::string::npos) << e;
  e = error_of(write("b.yaml", "trian:\n  iterations: 5\n"));
  EXPECT_NE(e.find("unknown section 'trian'"), std::string::npos) << e;
  e = error_of(write("c.yaml", "train:\n  iterations: -3\n"));
  EXPECT_NE(e.find("train.iterations"), std::string::npos) << e;
  e = error_of(write("d.yaml", "eval:\n  geometry: maybe\n"));
  EXPECT_NE(e.find("eval.geometry: expected true or false"), std::string::npos) << e;
  e = error_of(write("e.yaml", "train: [1, 2\n"));
  EXPECT_NE(e.find("YAML error"), std::string::npos) << e;
  e = error_of(write("g.yaml", "train:\n  iterations: 5\n  iterations: 7\n"));
  EXPECT_NE(e.find("'train.iterations' given twice"), std::string::npos) << e;
  e = error_of(write("f.yaml", "train:\n  extra_args: --resume\n"));
  EXPECT_NE(e.find("expected a list"), std::string::npos) << e;
}

TEST_F(RunParts, ContentHashFollowsContentNotTime) {
  const fs::path a = write("d/x.txt", "hello");
  write("d/sub/y.txt", "world");
  const std::string file = hash_path(a), folder = hash_path(dir_ / "d");
  EXPECT_EQ(file.size(), 16u);
  EXPECT_EQ(hash_path(write("d/x.txt", "hello")), file);  // rewritten, same bytes
  EXPECT_EQ(hash_path(dir_ / "d"), folder);
  write("d/x.txt", "hellp");
  EXPECT_NE(hash_path(a), file);
  EXPECT_NE(hash_path(dir_ / "d"), folder);
  write("d/x.txt", "hello");
  fs::rename(dir_ / "d/sub/y.txt", dir_ / "d/sub/z.txt");  // a renamed file changes the folder's hash
  EXPECT_NE(hash_path(dir_ / "d"), folder);
  EXPECT_NE(hash_text(""), hash_text(std::string(1, '\0')));  // the length counts
  EXPECT_THROW(hash_path(dir_ / "missing"), io::IoError);
}

TEST_F(RunParts, InputKinds) {
  write("scene/scene.yaml", "");
  write("x.bag", "");
  write("cams.xml", "");
  write("colmap/sparse/0/cameras.bin", "");
  write("log/result/a.txt", "");
  write("log/pcd/map.pcd", "");
  write("notes.txt", "");
  EXPECT_EQ(detect_input_kind((dir_ / "scene").string()), InputKind::kScene);
  EXPECT_EQ(detect_input_kind((dir_ / "x.bag").string()), InputKind::kRosBag);
  EXPECT_EQ(detect_input_kind((dir_ / "cams.xml").string()), InputKind::kMetashape);
  EXPECT_EQ(detect_input_kind((dir_ / "colmap").string()), InputKind::kColmap);
  EXPECT_EQ(detect_input_kind((dir_ / "log").string()), InputKind::kLivo2);
  EXPECT_EQ(detect_input_kind("synth:street"), InputKind::kSynthetic);
  EXPECT_EQ(synthetic_preset("synth:street"), "street");
  EXPECT_EQ(detect_input_kind((dir_ / "notes.txt").string()), InputKind::kUnknown);
  EXPECT_EQ(detect_input_kind((dir_ / "missing").string()), InputKind::kUnknown);
  EXPECT_EQ(detect_input_kind(dir_.string()), InputKind::kUnknown);  // a folder of unrelated things
}

TEST(Report, TraceCurveOfAResumedRun) {
  // Session 1 reported up to iteration 150, then was killed; the checkpoint was at 100, so session 2 starts
  // again at 101: the records from 101 on of session 1 are dropped, and session 2's clock continues from the
  // last kept record (iteration 100 at 20 s).
  const std::string text =
      "{\"iteration\":1,\"session_s\":1.0,\"loss\":0.5,\"gaussians\":10}\n"
      "{\"iteration\":100,\"session_s\":20.0,\"loss\":0.3,\"gaussians\":12}\n"
      "{\"iteration\":150,\"session_s\":30.0,\"loss\":0.2,\"gaussians\":13}\n"
      "{\"iteration\":15"  // cut short by the kill
      "\n{\"iteration\":101,\"session_s\":2.0,\"loss\":0.29,\"gaussians\":12}\n"
      "{\"iteration\":200,\"session_s\":22.0,\"loss\":0.1,\"gaussians\":14}\n";
  const nlohmann::json c = nlohmann::json::parse(trace_curve_json(text));
  ASSERT_EQ(c.size(), 4u);
  EXPECT_EQ(c[1]["iteration"], 100);
  EXPECT_EQ(c[2]["iteration"], 101);
  EXPECT_DOUBLE_EQ(c[2]["seconds"].get<double>(), 22.0);
  EXPECT_DOUBLE_EQ(c[3]["seconds"].get<double>(), 42.0);
}

TEST(Report, EachBlockOfATrainingInBlocksHasItsOwnCurve) {
  const std::filesystem::path train =
      std::filesystem::temp_directory_path() / ("litgs-report-blocks-" + std::to_string(::getpid()));
  std::filesystem::remove_all(train);
  std::filesystem::create_directories(train / "partition/blocks/block-0-0/train");
  std::ofstream(train / "partition/blocks/block-0-0/train/trace.jsonl")
      << "{\"iteration\":1,\"session_s\":1.0,\"loss\":0.5,\"gaussians\":10}\n"
         "{\"iteration\":50,\"session_s\":9.0,\"loss\":0.2,\"gaussians\":40}\n";
  const nlohmann::json metrics = {
      {"blocks",
       {{{"name", "block-0-0"}, {"trace", "partition/blocks/block-0-0/train/trace.jsonl"}},
        {{"name", "block-1-0"}, {"trace", "partition/blocks/block-1-0/train/trace.jsonl"}},  // trained before
        {{"name", "block-2-0"}}}}};  // an older record
  const nlohmann::json curves = block_curves_json(train, metrics);
  ASSERT_EQ(curves.size(), 1u) << curves.dump();
  EXPECT_EQ(curves[0]["name"], "block-0-0");
  ASSERT_EQ(curves[0]["curve"].size(), 2u);
  EXPECT_EQ(curves[0]["curve"][1]["gaussians"], 40);
  EXPECT_DOUBLE_EQ(curves[0]["curve"][1]["seconds"].get<double>(), 9.0);
  EXPECT_TRUE(block_curves_json(train, {{"gaussians", 5}}).empty());  // one training: no blocks
  std::filesystem::remove_all(train);
}

// One table row per budget tried, from its <tr to its </tr>.
std::string table_row(const std::string& html, const std::string& first_cell) {
  const size_t cell = html.find("><td>" + first_cell + "</td>");
  if (cell == std::string::npos) return "";
  const size_t start = html.rfind("<tr", cell);
  return html.substr(start, html.find("</tr>", cell) - start);
}

TEST(Report, BudgetSectionOfASearchMarksTheKeptBudgetAndWhy) {
  const nlohmann::json budget = nlohmann::json::parse(R"({
    "gaussians": 20000, "source": "search", "reference": 20000, "parsimony_se": 0.0, "min_gain_db": 0.1,
    "folds": 2, "trials": [
      {"budget": 10000, "validation_psnr_db": 33.24, "validation_psnr_db_per_fold": [34.16, 32.32],
       "gaussians": 10000, "initial_gaussians": 10000, "wall_s": 60.5},
      {"budget": 20000, "validation_psnr_db": 34.04, "validation_psnr_db_per_fold": [34.99, 33.09],
       "gaussians": 20000, "initial_gaussians": 15000, "wall_s": 144.0},
      {"budget": 40000, "failure": "out of memory allocating buffer 'gaussians: sh'"},
      {"budget": 80000, "validation_psnr_db": 33.5, "gaussians": 46491, "initial_gaussians": 15000}]})");
  const std::string html = budget_section_html(budget, 20000);
  EXPECT_NE(html.find("kept <b>20000</b>"), std::string::npos) << html;
  EXPECT_NE(html.find("rose above the best before it by at least 0.10 dB"), std::string::npos) << html;
  nlohmann::json any_rise = budget;
  any_rise["min_gain_db"] = 0.0;
  const std::string any_rise_html = budget_section_html(any_rise, 20000);
  EXPECT_NE(any_rise_html.find("rose above the best before it."), std::string::npos) << any_rise_html;
  const std::string filled = table_row(html, "10000"), kept = table_row(html, "20000"),
                    failed = table_row(html, "40000");
  EXPECT_NE(filled.find("<td>33.24</td><td>34.16 / 32.32</td>"), std::string::npos) << filled;
  EXPECT_NE(filled.find("filled by its initialization"), std::string::npos) << filled;
  EXPECT_EQ(filled.find("kept"), std::string::npos) << filled;
  EXPECT_NE(kept.find("class=kept"), std::string::npos) << kept;
  EXPECT_EQ(kept.find("filled"), std::string::npos) << kept;
  EXPECT_NE(failed.find("does not fit the device"), std::string::npos) << failed;
  EXPECT_NE(table_row(html, "80000").find("training did not fill it"), std::string::npos) << html;
  EXPECT_EQ(kept.find("did not fill"), std::string::npos) << kept;
}

TEST(Report, BudgetSectionOfAFixedOrDerivedBudget) {
  EXPECT_NE(budget_section_html(nullptr, 40000).find("fixed budget"), std::string::npos);
  const nlohmann::json derived = {
      {"gaussians", 179219},       {"source", "<LiDAR map>"}, {"points", 3988},
      {"points_seen", 3988},       {"surface_m2", 173.04},    {"surface_pixels", 716874},
      {"pixels_per_gaussian", 4.0}};
  const std::string html = budget_section_html(derived, 179219);
  EXPECT_NE(html.find("<b>179219</b> Gaussians from 3988 of 3988 points seen (&lt;LiDAR map&gt;)"),
            std::string::npos)
      << html;
  EXPECT_NE(html.find("173.0 m<sup>2</sup>"), std::string::npos) << html;
}

// metrics.json's budget_growth as BudgetGrowth::to_json writes it: a phase that waited, two that grew, the
// one that stopped.
const char* const kGrowth = R"json({
  "budget": 20000, "ceiling": 8000000, "stop_reason": "stop: validation gained -0.210 dB (standard error 0.040 dB)",
  "phases": [
    {"iteration": 600, "budget": 5000, "gaussians": 4729, "validation_psnr_db": null, "gain_db": null,
     "gain_se_db": null, "training_psnr_db": null, "training_gain_db": null, "wall_s": 20.5,
     "decision": "wait: the model has not filled its budget"},
    {"iteration": 900, "budget": 5000, "gaussians": 5000, "validation_psnr_db": 21.35, "gain_db": null,
     "gain_se_db": null, "training_psnr_db": 22.0, "training_gain_db": null, "wall_s": 31.0,
     "decision": "grow: first score; budget 10000"},
    {"iteration": 1200, "budget": 10000, "gaussians": 10000, "validation_psnr_db": 21.53, "gain_db": 0.18,
     "gain_se_db": 0.28, "training_psnr_db": 22.9, "training_gain_db": 0.91, "wall_s": 45.0,
     "decision": "grow: validation gained 0.180 dB; budget 20000"},
    {"iteration": 1500, "budget": 20000, "gaussians": 20000, "validation_psnr_db": 21.32, "gain_db": -0.21,
     "gain_se_db": 0.04, "training_psnr_db": 23.4, "training_gain_db": 0.5, "wall_s": 61.0,
     "decision": "stop: validation gained -0.210 dB (standard error 0.040 dB)"}],
  "last_scored_view_psnr_db": [21.0, 21.6], "last_scored_training_psnr_db": [23.0, 23.8]
})json";

TEST(Report, GrowthSectionShowsEachPhaseWhereItStoppedAndWhy) {
  const nlohmann::json growth = nlohmann::json::parse(kGrowth);
  const std::string html = growth_section_html(growth);
  EXPECT_NE(html.find("from a budget of 5000 to <b>20000</b> (ceiling 8000000)"), std::string::npos) << html;
  EXPECT_NE(html.find("Stopped: validation gained -0.210 dB (standard error 0.040 dB)."), std::string::npos)
      << html;
  EXPECT_NE(html.find("id=growth_gaussians"), std::string::npos);
  EXPECT_NE(html.find("id=growth_time"), std::string::npos);
  const std::string waited = table_row(html, "600"), grew = table_row(html, "1200"),
                    stopped = table_row(html, "1500");
  EXPECT_NE(waited.find("<td>&ndash;</td>"), std::string::npos) << waited;  // not scored
  EXPECT_NE(grew.find("<td>0.18 &plusmn; 0.28</td><td>0.91</td>"), std::string::npos) << grew;
  EXPECT_EQ(grew.find("class=kept"), std::string::npos) << grew;
  EXPECT_NE(stopped.find("class=kept"), std::string::npos) << stopped;

  const nlohmann::json chart = growth_chart_json(growth);
  ASSERT_EQ(chart.size(), 3u) << chart.dump();  // the scored phases only
  EXPECT_EQ(chart[0]["gaussians"], 5000);
  EXPECT_DOUBLE_EQ(chart[1]["seconds"].get<double>(), 45.0);
  EXPECT_FALSE(chart[1]["stop"].get<bool>());
  EXPECT_TRUE(chart[2]["stop"].get<bool>());
}

TEST(Report, GrowthThatNeverScoredHasNoChartsAndADamagedRecordSaysSo) {
  nlohmann::json growth = nlohmann::json::parse(kGrowth);
  growth["phases"] = nlohmann::json::array({growth["phases"][0]});
  growth["stop_reason"] = "1 validation view(s) cannot measure the noise of a gain";
  const std::string html = growth_section_html(growth);
  EXPECT_TRUE(growth_chart_json(growth).is_null());
  EXPECT_EQ(html.find("growth_gaussians"), std::string::npos) << html;
  EXPECT_NE(html.find("Stopped: 1 validation view(s) cannot measure"), std::string::npos) << html;
  growth["phases"] = nlohmann::json::array();  // a training too short for any phase
  EXPECT_NE(growth_section_html(growth).find("kept at its start, <b>20000</b>"), std::string::npos);
  const std::string damaged = growth_section_html({{"budget", "<many>"}, {"phases", 3}});
  EXPECT_NE(damaged.find("is not a growth record"), std::string::npos) << damaged;
}

TEST(Report, ADamagedBudgetRecordSaysSoInItsSection) {
  // Unparsable JSON reaches the section as a discarded value; wrong types as they are.
  const std::string unparsable =
      budget_section_html(nlohmann::json::parse("{\"gaussians\": ", nullptr, false), 1);
  EXPECT_NE(unparsable.find("is not a budget record"), std::string::npos) << unparsable;
  const std::string wrong_type = budget_section_html(
      {{"source", "search"}, {"gaussians", "<many>"}, {"trials", nlohmann::json::array()}}, 1);
  EXPECT_NE(wrong_type.find("is not a budget record"), std::string::npos) << wrong_type;
}

TEST(Report, Base64TestVectors) {  // RFC 4648, section 10
  EXPECT_EQ(base64(""), "");
  EXPECT_EQ(base64("f"), "Zg==");
  EXPECT_EQ(base64("fo"), "Zm8=");
  EXPECT_EQ(base64("foo"), "Zm9v");
  EXPECT_EQ(base64("foob"), "Zm9vYg==");
  EXPECT_EQ(base64("fooba"), "Zm9vYmE=");
  EXPECT_EQ(base64("foobar"), "Zm9vYmFy");
  EXPECT_EQ(base64(std::string("\xff\x00\xfe", 3)), "/wD+");
}

}  // namespace
}  // namespace litgs::host::run
