#include "host/run/report_html.h"

#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "host/run/report_budget.h"
#include "host/run/report_growth.h"
#include "io/error.h"

// Chart.js (MIT, Debian libjs-chart.js), embedded at build time by cmake/EmbedFile.cmake.
extern const char litgs_chart_js[];

namespace litgs::host::run {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

std::string read_text(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw io::IoError(path, 0, "cannot open (needed by the report)");
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

json read_json(const fs::path& path) {
  try {
    return json::parse(read_text(path));
  } catch (const json::exception& e) {
    throw io::IoError(path, 0, std::string("not valid JSON: ") + e.what());
  }
}

// JSON inside <script>: "</" would end the element.
std::string script_json(const json& j) {
  std::string s = j.dump();
  for (size_t p = 0; (p = s.find("</", p)) != std::string::npos; p += 3) s.replace(p, 2, "<\\/");
  return s;
}

std::string row(const std::string& name, const std::string& value, const std::string& note = "") {
  return "<tr><th>" + name + "</th><td>" + value + "</td><td class=note>" + note + "</td></tr>\n";
}

// A share in [0, 1] as a percentage; a dash, as number() writes, for a missing value.
std::string percent(const json& share) {
  return number(share.is_number() ? json(100 * share.get<double>()) : json(), 1);
}

std::string summary_table(const json& metrics, const json& eval) {
  const json& emd = eval.at("emd");
  std::string t = "<table class=summary>\n";
  t += row("held-out PSNR", number(eval["psnr_db"], 2, " dB"), escape_html(eval.value("image_units", "")));
  if (eval.value("covisible_psnr_db", json()).is_number())
    t += row("held-out PSNR, covisible pixels", number(eval["covisible_psnr_db"], 2, " dB"),
             "over the " + percent(eval.value("covisible_fraction", json())) +
                 "% of held-out pixels whose true surface a training view also saw (gt/depth)");
  t += row("held-out SSIM", number(eval["ssim"], 4), "11-tap Gaussian window, sigma 1.5");
  if (eval["mae_counts"].is_number())
    t += row("mean absolute error", number(eval["mae_counts"], 1, " counts"), "16-bit raw counts");
  t += row("LPIPS", "not available", escape_html(eval.value("lpips", "")));
  if (emd.is_object())
    t += row("EMD", number(emd["mean_m"], 4, " m") + " &plusmn; " + number(emd["std_m"], 4),
             "against " + escape_html(emd.value("reference", "")) +
                 ", N = " + std::to_string(emd.value("samples", 0)) + ", " +
                 std::to_string(emd.value("rounds", 0)) + " draws; sampling floor " +
                 number(emd["floor_m"], 4, " m") + "; inside the region the training views see");
  const json region = eval.value("observed_region", json());
  if (region.is_object())
    t += row("observed region", percent(region["reference_observed_fraction"]) + "% of the reference",
             percent(region["covered_fraction"]) + "% of it has a Gaussian centre within " +
                 number(region["coverage_radius_m"], 2, " m"));
  t +=
      row("depth to planes (RMSE)", number(eval["depth_plane_rmse_m"], 4, " m"),
          escape_html(eval["plane_reference"].is_string() ? eval["plane_reference"].get<std::string>() : ""));
  t += row("Gaussian centres to planes (RMS)", number(eval["centre_plane_rms_m"], 4, " m"),
           "median " + number(eval["centre_plane_median_m"], 4, " m"));
  t += row("render", number(eval["render_ms_per_frame"], 1, " ms/frame"),
           std::to_string(eval.value("width", 0)) + "x" + std::to_string(eval.value("height", 0)) + ", " +
               escape_html(eval.value("device", "")));
  t += row("Gaussians", std::to_string(eval.value("gaussians", 0)));
  t += row("training", number(metrics["wall_s"], 1, " s"),
           number(metrics["ms_per_iteration"], 1, " ms/iteration, ") +
               std::to_string(metrics.value("iterations", 0)) + " iterations");
  if (metrics["peak_device_bytes"].is_number())
    t += row("peak device memory", number(json(metrics["peak_device_bytes"].get<double>() / 1e6), 0, " MB"),
             "training");
  const json& trajectory = eval.value("trajectory", json("not available: eval wrote no trajectories"));
  if (trajectory.is_object() && !trajectory["ate_m"].is_number()) {
    t += row("ATE", "not available", "the scene has no gt/poses.txt");
    t += row("refinement moved the frames", number(trajectory["moved_mean_m"], 4, " m"),
             "mean over " + std::to_string(trajectory.value("pairs", 0)) + " frames, at most " +
                 number(trajectory["moved_max_m"], 4, " m") + " (poses_prior.txt to poses.txt)");
  } else if (trajectory.is_object()) {
    const std::string how = escape_html(trajectory.value("alignment", "")) + ", " +
                            std::to_string(trajectory.value("pairs", 0)) + " frames, against gt/poses.txt";
    if (trajectory["ate_prior_m"].is_number())
      t +=
          row("ATE before refinement", number(trajectory["ate_prior_m"], 4, " m"), "poses_prior.txt; " + how);
    t += row(trajectory["ate_prior_m"].is_number() ? "ATE after refinement" : "ATE",
             number(trajectory["ate_m"], 4, " m"), "poses.txt; " + how);
  } else {
    t += row("ATE", "not available", escape_html(trajectory.get<std::string>()));
  }
  return t + "</table>\n";
}

std::string stages_table(const json& run) {
  if (!run.is_object()) return "<p>run.json not found: stage timings unknown.</p>\n";
  std::string t =
      "<table class=stages><tr><th>stage</th><th>status</th><th>seconds</th><th>peak host memory</th></tr>\n";
  for (const json& s : run.value("stages", json::array())) {
    std::string status = s.value("status", "");
    // refine says what it did: refined, kept the priors (the held-back tracks judged it worse) or stopped.
    if (const json m = s.value("metrics", json::object()); m.is_object() && m.contains("outcome"))
      status += ": " + m["outcome"].get<std::string>() +
                (m.contains("tracks") ? " (" + m["tracks"].get<std::string>() + " tracks)" : "");
    t += "<tr><td>" + escape_html(s.value("name", "")) + "</td><td>" + escape_html(status) + "</td><td>" +
         number(s.value("seconds", json()), 1) + "</td><td>" +
         (s.contains("peak_host_bytes") ? number(json(s["peak_host_bytes"].get<double>() / 1e6), 0, " MB")
                                        : "&ndash;") +
         "</td></tr>\n";
  }
  return t + "</table>\n";
}

std::string views_html(const json& eval, const fs::path& eval_dir, unsigned max_views) {
  if (!eval.contains("pictures")) return "<p>No pictures (eval ran without --views-out).</p>\n";
  const json& pictures = eval["pictures"];
  const fs::path folder = pictures.at("folder").get<std::string>();
  const fs::path dir = folder.is_absolute() ? folder : eval_dir / folder;
  std::string out;
  unsigned shown = 0;
  for (const json& v : pictures.at("views")) {
    if (shown++ >= max_views) break;
    out += "<div class=view><div class=vname>" + escape_html(v.value("name", "")) + "</div>\n";
    const std::pair<const char*, std::string> cells[] = {
        {"render", "render"},
        {"target", "real frame"},
        {"error", "|error| (white: " + number(pictures.at("error_full_scale"), 2) + ")" +
                      (v.value("error_uncovered_shown", false) ? "; blue: no training view saw it" : "")},
        {"false_colour", "render, thermal palette"},
        {"depth", "depth " + number(v["depth_min_m"], 2) + "&ndash;" + number(v["depth_max_m"], 2) + " m"}};
    for (const auto& [key, caption] : cells)
      out += "<figure><img alt=\"" + std::string(key) + "\" src=\"data:image/png;base64," +
             base64(read_text(dir / v.at(key).get<std::string>())) + "\"><figcaption>" + caption +
             "</figcaption></figure>\n";
    out += "</div>\n";
  }
  return out;
}

std::string per_view_table(const json& eval) {
  std::string t =
      "<table class=views><tr><th>view</th><th>PSNR dB</th><th>SSIM</th><th>MAE counts</th><th>depth "
      "RMSE m</th><th>render ms</th><th>covisible PSNR dB</th><th>covisible %</th></tr>\n";
  for (const json& v : eval.at("views"))
    t += "<tr><td>" + escape_html(v.value("name", "")) + "</td><td>" + number(v["psnr_db"], 2) + "</td><td>" +
         number(v["ssim"], 4) + "</td><td>" + number(v["mae_counts"], 1) + "</td><td>" +
         number(v["depth_plane_rmse_m"], 4) + "</td><td>" + number(v["render_ms"], 1) + "</td><td>" +
         number(v.value("covisible_psnr_db", json()), 2) + "</td><td>" +
         percent(v.value("covisible_fraction", json())) + "</td></tr>\n";
  return t + "</table>\n";
}

const char* kStyle = R"(
body{font:14px sans-serif;margin:0;padding:0 16px;background:#fff;color:#222;width:1200px}
h1{font-size:20px;height:28px;margin:8px 0}
h2{font-size:16px;margin:18px 0 6px}
#charts,.charts{display:flex;gap:12px;height:300px}
.chart{width:291px;height:300px;position:relative}
.none{display:flex;align-items:center;justify-content:center;color:#666;border:1px solid #ccc}
.view{display:flex;gap:8px;height:196px;align-items:flex-start}
.vname{width:90px;font-size:12px;overflow-wrap:anywhere}
figure{margin:0}
figure img{height:160px;image-rendering:pixelated;display:block}
figcaption{font-size:11px;color:#555}
table{border-collapse:collapse;margin:4px 0}
td,th{border:1px solid #ccc;padding:2px 8px;text-align:left}
td.note{color:#666;font-size:12px}
tr.kept td{font-weight:bold;background:#eef6ee}
)";

// Builds the charts from the data block; sets body[data-charts] to the number drawn (the browser test reads
// it). Animation off: the first frame is the final picture.
const char* kChartsScript = R"(
(function(){
  const d = JSON.parse(document.getElementById('data').textContent);
  const evalAt = d.evaluations.map(e => ({x: e.iteration, y: e.psnr_db}));
  const timeAt = it => { const t = d.trace; if (!t.length) return null;
    let k = t.findIndex(p => p.iteration >= it); if (k < 0) return t[t.length-1].seconds; if (k == 0) return t[0].seconds;
    const a = t[k-1], b = t[k]; return a.seconds + (b.seconds-a.seconds)*(it-a.iteration)/Math.max(1,b.iteration-a.iteration); };
  const axis = (title) => ({type:'linear', title:{display:true, text:title}});
  const common = {animation:false, responsive:true, maintainAspectRatio:false, parsing:false,
                  plugins:{legend:{display:true}}};
  const make = (id, datasets, x, y, y2) => {
    const scales = {x: axis(x), y: Object.assign(axis(y), {position:'left'})};
    if (y2) scales.y2 = Object.assign(axis(y2), {position:'right', grid:{drawOnChartArea:false}});
    new Chart(document.getElementById(id), {type:'line', data:{datasets:datasets},
      options:Object.assign({scales:scales}, common)}); };
  const line = (label, data, colour, axisId) => ({label:label, data:data, borderColor:colour,
      backgroundColor:colour, pointRadius:3, borderWidth:2, yAxisID:axisId||'y'});
  // One training's curve, or one per block of a training in blocks (each block's own clock).
  const palette = ['#1f77b4', '#2ca02c', '#9467bd', '#e377c2', '#7f7f7f', '#bcbd22', '#17becf', '#8c564b'];
  const curves = d.blocks.length ? d.blocks.map((b, k) => ({label: ' (' + b.name + ')', curve: b.curve,
      colour: palette[k % palette.length]})) : [{label: '', curve: d.trace, colour: '#1f77b4'}];
  const losses = x => curves.map(c => line('training loss' + c.label, c.curve.map(p => ({x:p[x], y:p.loss})),
      c.colour, 'y2'));
  make('psnr_iter', [line('held-out PSNR (dB)', evalAt, '#d62728')].concat(losses('iteration')),
       'iteration', 'PSNR (dB)', 'loss');
  make('psnr_time', [line('held-out PSNR (dB)', d.evaluations.map(e => ({x:timeAt(e.iteration), y:e.psnr_db})), '#d62728')]
                      .concat(losses('seconds')),
       'training time (s)', 'PSNR (dB)', 'loss');
  make('gaussians', curves.map(c => line('Gaussians' + c.label, c.curve.map(p => ({x:p.iteration, y:p.gaussians})),
       d.blocks.length ? c.colour : '#2ca02c')), 'iteration', 'Gaussians');
  let drawn = 3;
  // A budget grown inside the training: validation PSNR against its size and against time, the phase that
  // stopped the growth drawn larger.
  if (d.growth) {
    const grown = (x) => Object.assign(line('validation PSNR (dB)', d.growth.map(p => ({x:p[x], y:p.psnr_db})), '#8c564b'),
        {pointRadius: d.growth.map(p => p.stop ? 7 : 3)});
    make('growth_gaussians', [grown('gaussians')], 'Gaussians', 'validation PSNR (dB)');
    make('growth_time', [grown('seconds')], 'training time (s)', 'validation PSNR (dB)');
    drawn += 2;
  }
  // The trajectories seen from above and from the side, the same metres per pixel on both axes of each
  // (about: the chart areas are near square).
  const view = (id, t, label) => {
    const all = t.truth.concat(t.prior, t.estimate);
    const lo = k => Math.min(...all.map(p => p[k])), hi = k => Math.max(...all.map(p => p[k]));
    const half = 0.55 * Math.max(hi(0) - lo(0), hi(1) - lo(1), 1e-6);
    const mid = k => (lo(k) + hi(k)) / 2, xy = v => v.map(p => ({x:p[0], y:p[1]}));
    const sets = t.truth.length ?
      [Object.assign(line('truth', xy(t.truth), '#9467bd'), {borderWidth:6, pointRadius:0, order:3})] : [];
    if (t.prior.length) sets.push(Object.assign(line('prior', xy(t.prior), '#ff7f0e'), {pointRadius:2, order:2}));
    sets.push(Object.assign(line(t.prior.length ? 'refined' : 'estimate', xy(t.estimate), '#17becf'),
                            {pointRadius:2, order:1}));
    const scales = {x: Object.assign(axis('m (' + label + ')'), {min:mid(0) - half, max:mid(0) + half}),
                    y: Object.assign(axis('m'), {min:mid(1) - half, max:mid(1) + half})};
    new Chart(document.getElementById(id), {type:'line', data:{datasets:sets},
      options:Object.assign({scales:scales}, common)});
    ++drawn;
  };
  if (d.trajectory) {
    view('trajectory', d.trajectory.top_view, 'top view');
    if (d.trajectory.side_view) view('trajectory_side', d.trajectory.side_view, 'side view');
  }
  document.body.setAttribute('data-charts', String(drawn));
})();
)";

}  // namespace

std::string escape_html(const std::string& s) {
  std::string out;
  for (char c : s) {
    if (c == '<')
      out += "&lt;";
    else if (c == '>')
      out += "&gt;";
    else if (c == '&')
      out += "&amp;";
    else if (c == '"')
      out += "&quot;";
    else
      out += c;
  }
  return out;
}

json json_field(const json& j, const char* key) {
  return j.value(key, json());
}

std::string html_cell(const std::string& html) {
  return "<td>" + html + "</td>";
}

std::string number(const json& v, int digits, const std::string& unit) {
  if (!v.is_number()) return "&ndash;";
  std::ostringstream s;
  s.setf(std::ios::fixed);
  s.precision(digits);
  s << v.get<double>() << unit;
  return s.str();
}

std::string base64(const std::string& bytes) {
  static const char* table = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((bytes.size() + 2) / 3 * 4);
  size_t i = 0;
  for (; i + 2 < bytes.size(); i += 3) {
    const uint32_t v = (uint32_t{static_cast<uint8_t>(bytes[i])} << 16) |
                       (uint32_t{static_cast<uint8_t>(bytes[i + 1])} << 8) |
                       static_cast<uint8_t>(bytes[i + 2]);
    out += {table[v >> 18], table[(v >> 12) & 63], table[(v >> 6) & 63], table[v & 63]};
  }
  if (i + 1 == bytes.size()) {
    const uint32_t v = uint32_t{static_cast<uint8_t>(bytes[i])} << 16;
    out += {table[v >> 18], table[(v >> 12) & 63], '=', '='};
  } else if (i + 2 == bytes.size()) {
    const uint32_t v = (uint32_t{static_cast<uint8_t>(bytes[i])} << 16) |
                       (uint32_t{static_cast<uint8_t>(bytes[i + 1])} << 8);
    out += {table[v >> 18], table[(v >> 12) & 63], table[(v >> 6) & 63], '='};
  }
  return out;
}

std::string trace_curve_json(const std::string& text) {
  json curve = json::array();
  std::istringstream in(text);
  std::string line;
  int previous_iteration = -1;
  double offset_s = 0;  // seconds before the current session
  while (std::getline(in, line)) {
    if (line.empty()) continue;
    json r;
    try {
      r = json::parse(line);
    } catch (const json::exception&) {
      continue;  // a line cut short by an interruption
    }
    if (!r.contains("iteration") || !r.contains("session_s")) continue;
    const int it = r["iteration"].get<int>();
    if (it <= previous_iteration) {
      // A resumed session: drop what the interrupted one reported from here on, continue its clock.
      while (!curve.empty() && curve.back()["iteration"].get<int>() >= it) curve.erase(curve.size() - 1);
      offset_s = curve.empty() ? 0.0 : curve.back()["seconds"].get<double>();
    }
    curve.push_back({{"iteration", it},
                     {"seconds", offset_s + r["session_s"].get<double>()},
                     {"loss", r.value("loss", json())},
                     {"gaussians", r.value("gaussians", json())},
                     {"psnr_db", r.value("psnr_db", json())}});
    previous_iteration = it;
  }
  return curve.dump();
}

json block_curves_json(const fs::path& train_dir, const json& metrics) {
  json out = json::array();
  for (const json& b : metrics.value("blocks", json::array())) {
    const json trace = json_field(b, "trace");
    if (!trace.is_string() || !fs::exists(train_dir / trace.get<std::string>())) continue;
    out.push_back(
        {{"name", b.value("name", "")},
         {"curve", json::parse(trace_curve_json(read_text(train_dir / trace.get<std::string>())))}});
  }
  return out;
}

std::string report_html(const fs::path& run_dir, unsigned max_views) {
  const json metrics = read_json(run_dir / "train" / "metrics.json");
  const json eval = read_json(run_dir / "eval" / "eval.json");
  const json run = fs::exists(run_dir / "run.json") ? read_json(run_dir / "run.json") : json();
  const json trace = json::parse(trace_curve_json(read_text(run_dir / "train" / "trace.jsonl")));
  json evaluations = json::array();
  for (const json& e : metrics.value("evaluations", json::array()))
    evaluations.push_back({{"iteration", e.at("iteration")}, {"psnr_db", e.at("psnr_db")}});
  const json trajectory = eval.value("trajectory", json());
  const json growth = metrics.value("budget_growth", json());
  const json data = {{"trace", trace},
                     {"blocks", block_curves_json(run_dir / "train", metrics)},
                     {"evaluations", evaluations},
                     {"growth", growth.is_null() ? json() : growth_chart_json(growth)},
                     {"trajectory", trajectory.is_object() ? trajectory : json(nullptr)}};

  std::string h =
      "<!DOCTYPE html>\n<html lang=en><head><meta charset=utf-8><title>LIT-GS run report</title>\n<style>";
  h += kStyle;
  h += "</style>\n<script>\n";
  h += litgs_chart_js;
  h += "\n</script>\n</head><body>\n<h1>LIT-GS run: " +
       escape_html(run.is_object() ? run.value("input", "") : run_dir.string()) + "</h1>\n";
  h += "<div id=charts><div class=chart><canvas id=psnr_iter></canvas></div><div class=chart><canvas "
       "id=psnr_time></canvas></div><div class=chart><canvas id=gaussians></canvas></div>";
  h += trajectory.is_object()
           ? "<div class=chart><canvas id=trajectory></canvas></div><div class=chart><canvas "
             "id=trajectory_side></canvas></div>"
           : "<div class='chart none'>trajectories: " +
                 escape_html(trajectory.is_string() ? trajectory.get<std::string>() : "not available") +
                 "</div>";
  h += "</div>\n";
  h += "<h2>Held-out views</h2>\n" + views_html(eval, run_dir / "eval", max_views);
  h += "<h2>Summary</h2>\n" + summary_table(metrics, eval);
  const fs::path budget_file = run_dir / "train" / "budget.json";
  json budget;  // null: no record, a fixed budget
  if (fs::exists(budget_file))
    budget = json::parse(read_text(budget_file), nullptr, false);  // discarded if bad
  h += "<h2>Budget</h2>\n" + (budget.is_null() && !growth.is_null()
                                  ? growth_section_html(growth)
                                  : budget_section_html(budget, metrics.value("gaussians", uint64_t{0})));
  h += "<h2>Stages</h2>\n" + stages_table(run);
  h += "<h2>Held-out views, per view</h2>\n" + per_view_table(eval);
  h += "<script type=\"application/json\" id=data>" + script_json(data) + "</script>\n<script>";
  h += kChartsScript;
  h += "</script>\n</body></html>\n";
  return h;
}

}  // namespace litgs::host::run
