// report: DIR/report.html from the training's and the evaluation's outputs (`litgs-engine report`).
#include "host/run/stage.h"

namespace litgs::host::run {
namespace {

StagePlan plan(const StageContext& c) {
  StagePlan p;
  p.inputs = {c.stage_dir("train") / "metrics.json", c.stage_dir("train") / "trace.jsonl",
              c.stage_dir("eval") / "eval.json", c.stage_dir("eval") / "views"};
  p.options = section_json(c.config, "report");
  p.command = {"report",
               "--run",
               c.out_dir.string(),
               "--out",
               (c.out_dir / "report.html").string(),
               "--max-views",
               std::to_string(c.config.report.max_views)};
  p.outputs = {"report.html"};
  return p;
}

nlohmann::json result(const StageContext& c) {
  return {{"report", (c.out_dir / "report.html").string()}, {"metrics", nlohmann::json::object()}};
}

}  // namespace

Stage report_stage() {
  return {"report", "DIR/report.html", plan, result};
}

}  // namespace litgs::host::run
