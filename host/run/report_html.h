// DIR/report.html of a run: one self-contained file (Chart.js from Debian's libjs-chart.js inlined, pictures
// as PNG data URIs; nothing is fetched at view time). Sections: the charts (held-out PSNR and training loss
// against iterations and seconds, Gaussians over training, the trajectories' top view with truth, prior and
// refined poses where the scene has ground truth), the held-out views (render beside the real
// frame, error map, false colour, rendered depth), the summary of metrics, how the budget was chosen
// (report_budget.h; a budget grown inside the training, with its two charts: report_growth.h), the stages,
// the per-view table.
#pragma once

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

namespace litgs::host::run {

// Reads DIR/run.json (optional), DIR/train/budget.json (optional), DIR/train/metrics.json,
// DIR/train/trace.jsonl (a training in blocks: each block's), DIR/eval/eval.json and the pictures it lists.
// io::IoError naming a missing or malformed file.
std::string report_html(const std::filesystem::path& run_dir, unsigned max_views);

// The training's progress records as one curve: a resumed run appends records from its checkpoint's iteration
// on, so records at or after a restart's iteration from before the restart are dropped, and the restarted
// session's seconds continue from the last kept record. Returns [{iteration, seconds, loss, gaussians,
// psnr_db}] in iteration order.
std::string trace_curve_json(const std::string& trace_jsonl_text);

// A training in blocks (metrics.json's `blocks`, each with its `trace` relative to `train_dir`): each block's
// curve as trace_curve_json gives it, [{name, curve}], blocks without a trace file left out; [] for one
// training.
nlohmann::json block_curves_json(const std::filesystem::path& train_dir, const nlohmann::json& metrics);

// A JSON number with `digits` decimals and `unit` appended; an en dash (&ndash;) where it is not a number.
std::string number(const nlohmann::json& v, int digits, const std::string& unit = "");

// A field or null (a const json's operator[] on a missing key is undefined).
nlohmann::json json_field(const nlohmann::json& j, const char* key);

// One table cell: <td>html</td>.
std::string html_cell(const std::string& html);

// Text for HTML content and attribute values: < > & " escaped.
std::string escape_html(const std::string& s);

// RFC 4648 base64.
std::string base64(const std::string& bytes);

}  // namespace litgs::host::run
