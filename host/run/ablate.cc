#include "host/run/ablate.h"

#include <algorithm>
#include <cstdio>
#include <stdexcept>

#include "host/run/pipeline.h"
#include "io/atomic_file.h"

namespace litgs::host::run {
namespace {

using nlohmann::json;

// A stage's metric from a run's record; null where the stage did not run or has no such metric.
json metric(const json& record, const std::string& stage, const std::string& key) {
  for (const json& s : record.at("stages"))
    if (s.value("name", "") == stage) return s.value("metrics", json::object()).value(key, json());
  return nullptr;
}

std::string fixed(const json& v, int digits) {
  if (!v.is_number()) return "-";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.*f", digits, v.get<double>());
  return buf;
}

using Column = std::pair<std::string, std::function<std::string(const json&)>>;

Column column(const std::string& header, const std::string& stage, const std::string& key, int digits) {
  return {header, [=](const json& r) { return fixed(metric(r, stage, key), digits); }};
}

// Held-out PSNR over the pixels some training view saw (eval's covisibility, where the scene has true
// depth); "-" where it was not measured.
Column covisible_psnr_column() {
  return column("covisible PSNR (dB)", "eval", "covisible_psnr_db", 2);
}

// A stage's wall seconds from a run's record; "-" where it did not run (skipped or absent).
std::string stage_seconds(const json& record, const std::string& stage) {
  for (const json& s : record.at("stages"))
    if (s.value("name", "") == stage && s.contains("seconds")) return fixed(s["seconds"], 1);
  return "-";
}

// Table II: training on the input (drifting) poses, on the refined ones, and on the true ones (gt/poses.txt
// for training and for the held-out views alike: eval takes train.poses).
AblationStudy refine_study() {
  AblationStudy s{"refine", {"poses"}, {}, {}, ""};
  s.variants = {{"off", {"input (unrefined)"}, [](RunConfig& c) { c.refine.enabled = false; }},
                {"on", {"refined"}, [](RunConfig& c) { c.refine.enabled = true; }},
                {"truth", {"true (gt/poses.txt)"}, [](RunConfig& c) {
                   c.refine.enabled = false;
                   c.train.poses = "truth";
                 }}};
  // eval scores the poses training used: the truth run's ATE is of gt/poses.txt, measured like the others.
  s.measured = {column("ATE (m)", "eval", "ate_m", 4),
                column("PSNR (dB)", "eval", "psnr_db", 2),
                covisible_psnr_column(),
                column("SSIM", "eval", "ssim", 4),
                column("depth to planes RMSE (m)", "eval", "depth_plane_rmse_m", 4),
                {"refine (s)", [](const json& r) { return stage_seconds(r, "refine"); }},
                column("training (s)", "train", "wall_s", 1)};
  s.note =
      "ATE: SE(3) Umeyama against gt/poses.txt at the frame times, of the poses training used. Held-out "
      "views are rendered at the poses of their run (input, refined or true).";
  return s;
}

AblationStudy lambda_study() {
  AblationStudy s{"lambda", {"lambda_geo"}, {}, {}, ""};
  for (const double l : {0.0, 0.2, 0.4, 0.6, 0.8})
    s.variants.push_back({fixed(l, 1), {fixed(l, 1)}, [l](RunConfig& c) { c.train.lambda_geo = l; }});
  s.measured = {column("PSNR (dB)", "eval", "psnr_db", 2),
                covisible_psnr_column(),
                column("SSIM", "eval", "ssim", 4),
                column("depth to planes RMSE (m)", "eval", "depth_plane_rmse_m", 4),
                column("centres to planes RMS (m)", "eval", "centre_plane_rms_m", 4),
                column("EMD (m)", "eval", "emd_m", 3),
                column("training (s)", "train", "wall_s", 1)};
  return s;
}

AblationStudy features_study(const RunConfig& base) {
  AblationStudy s{"features", {"features", "CLAHE"}, {}, {}, ""};
  // With oracle tracks refine (and so train) does not depend on the features: stop after match.
  const bool tracks_from_frontend = base.refine.tracks != "oracle";
  // XFeat runs on the device with its own matcher (mutual nearest neighbours over a cosine bound, `match
  // --matcher auto`) and with LighterGlue (`--matcher lighterglue`); the classical detectors with the ratio
  // test. XFeat also on its input enlarged 2 and 3 times (`match --xfeat-scale`): finer keypoints and
  // descriptors at 4 and 9 times the network's cost.
  struct Detector {
    const char *name, *features, *matcher;
    double xfeat_scale;
  };
  for (const Detector d : {Detector{"orb", "orb", "auto", 1}, Detector{"sift", "sift", "auto", 1},
                           Detector{"akaze", "akaze", "auto", 1}, Detector{"xfeat", "xfeat", "auto", 1},
                           Detector{"xfeat-x2", "xfeat", "auto", 2}, Detector{"xfeat-x3", "xfeat", "auto", 3},
                           Detector{"xfeat-lighterglue", "xfeat", "lighterglue", 1}}) {
    std::string label = std::string(d.matcher) == "auto" ? d.features : "xfeat + lighterglue";
    if (d.xfeat_scale != 1) label += " (input x" + fixed(d.xfeat_scale, 0) + ")";
    for (const bool clahe : {false, true})
      s.variants.push_back({std::string(d.name) + (clahe ? "-clahe" : ""),
                            {label, clahe ? "yes" : "no"},
                            [d, clahe](RunConfig& c) {
                              c.match.features = d.features;
                              c.match.matcher = d.matcher;
                              c.match.xfeat_scale = d.xfeat_scale;
                              c.match.clahe = clahe;
                            },
                            tracks_from_frontend ? "eval" : "match"});
  }
  s.measured = {column("keypoints per image", "match", "keypoints_per_image", 0),
                column("inlier ratio", "match", "inlier_ratio", 3),
                {"verified / tried pairs",
                 [](const json& r) {
                   return fixed(metric(r, "match", "pairs_verified"), 0) + " / " +
                          fixed(metric(r, "match", "pairs_tried"), 0);
                 }},
                column("points", "match", "points", 0),
                column("mean track length", "match", "mean_track_length", 2),
                column("reprojection (px)", "match", "mean_reprojection_error_px", 2),
                {"match (s)", [](const json& r) { return stage_seconds(r, "match"); }}};
  if (tracks_from_frontend) {
    s.measured.push_back(column("ATE (m)", "eval", "ate_m", 4));
    s.measured.push_back({"plane RMS after refinement (m)", [](const json& r) {
                            const json p = metric(r, "refine", "plane_rms_m");
                            return p.is_array() ? fixed(p[1], 4) : std::string("-");
                          }});
    s.measured.push_back(column("PSNR (dB)", "eval", "psnr_db", 2));
    s.measured.push_back(covisible_psnr_column());
  } else {
    s.note =
        "ATE, plane residual and PSNR are not measured per feature type here: refine.tracks is oracle "
        "(tracks projected from the synthetic scene's truth, an experiment), so refinement and training do "
        "not depend on the front end.";
  }
  return s;
}

// The budgets the strategy study compares: 1/4, 1/2 and 1 times a fixed train.max_gaussians; with auto or
// search or grow, the derived, searched or grown budget beside fixed ones spanning docs/budget.md's DUNR
// sweep (5k to 80k).
std::vector<std::string> compared_budgets(const std::string& base) {
  if (base == "auto" || base == "search" || base == "grow") return {"5000", "20000", "80000", base};
  const bool count = !base.empty() && base.find_first_not_of("0123456789") == std::string::npos &&
                     base.size() <= 9 && std::stoul(base) >= 4;
  if (!count)
    throw std::invalid_argument(
        "train.max_gaussians must be a count (at least 4), auto, search or grow, not '" + base + "'");
  const unsigned long b = std::stoul(base);
  return {std::to_string(b / 4), std::to_string(b / 2), base};
}

AblationStudy strategy_study(const RunConfig& base) {
  AblationStudy s{"strategy", {"strategy", "budget"}, {}, {}, ""};
  for (const char* strategy : {"adc", "mcmc"})
    for (const std::string& budget : compared_budgets(base.train.max_gaussians))
      s.variants.push_back(
          {std::string(strategy) + "-" + budget, {strategy, budget}, [strategy, budget](RunConfig& c) {
             c.train.strategy = strategy;
             c.train.max_gaussians = budget;
           }});
  s.measured = {column("Gaussians", "train", "gaussians", 0),
                column("PSNR (dB)", "eval", "psnr_db", 2),
                covisible_psnr_column(),
                column("SSIM", "eval", "ssim", 4),
                column("training (s)", "train", "wall_s", 1),
                column("ms/iteration", "train", "ms_per_iteration", 1)};
  s.note =
      "budget: MCMC's fixed number of Gaussians; ADC's cap; auto: derived from the scene's surface (`train "
      "--max-gaussians auto`); search: searched on validation views (`train --max-gaussians search`).";
  return s;
}

std::string markdown_row(const std::vector<std::string>& cells) {
  std::string row = "|";
  for (const std::string& c : cells) row.append(" ").append(c).append(" |");
  return row + "\n";
}

std::string markdown_table(const AblationStudy& s, const std::vector<json>& records) {
  std::vector<std::string> header = s.varied;
  for (const auto& column : s.measured) header.push_back(column.first);
  std::string t = markdown_row(header) + markdown_row(std::vector<std::string>(header.size(), "---"));
  for (size_t i = 0; i < s.variants.size(); ++i) {
    std::vector<std::string> cells = s.variants[i].cells;
    if (records[i].contains("failed")) {  // the row says why; its other cells stay empty
      cells.push_back("not run: " + records[i]["failed"].get<std::string>());
      cells.resize(header.size(), "-");
    } else {
      for (const auto& column : s.measured) cells.push_back(column.second(records[i]));
    }
    t += markdown_row(cells);
  }
  return t;
}

std::vector<std::string> split_commas(const std::string& text) {
  std::vector<std::string> parts;
  size_t start = 0;
  for (size_t comma; (comma = text.find(',', start)) != std::string::npos; start = comma + 1)
    parts.push_back(text.substr(start, comma - start));
  parts.push_back(text.substr(start));
  return parts;
}

}  // namespace

RunConfig ablation_base_config() {
  RunConfig c;
  c.train.max_gaussians = "40000";
  return c;
}

std::vector<AblationStudy> ablation_studies(const std::string& names, const RunConfig& base) {
  const std::vector<std::string> known = {"refine", "lambda", "features", "strategy"};
  std::vector<std::string> wanted;
  for (const std::string& name : split_commas(names)) {
    if (name == "all") {
      wanted = known;
    } else if (std::find(known.begin(), known.end(), name) != known.end()) {
      wanted.push_back(name);
    } else {
      throw std::invalid_argument("--study " + names + ": '" + name +
                                  "' is not a study (refine, lambda, features, strategy, all, or a "
                                  "comma-separated list of them)");
    }
  }
  std::vector<AblationStudy> studies;
  for (const std::string& name : known) {  // each once, in the order of `known`
    if (std::find(wanted.begin(), wanted.end(), name) == wanted.end()) continue;
    if (name == "refine") studies.push_back(refine_study());
    if (name == "lambda") studies.push_back(lambda_study());
    if (name == "features") studies.push_back(features_study(base));
    if (name == "strategy") studies.push_back(strategy_study(base));
  }
  return studies;
}

std::vector<AblationStudy> keep_variants(std::vector<AblationStudy> studies, const std::string& names) {
  if (names.empty()) return studies;
  const std::vector<std::string> wanted = split_commas(names);
  std::string known;
  for (const AblationStudy& s : studies)
    for (const AblationVariant& v : s.variants) known += (known.empty() ? "" : ", ") + v.name;
  for (const std::string& name : wanted) {
    const bool found = std::any_of(studies.begin(), studies.end(), [&](const AblationStudy& s) {
      return std::any_of(s.variants.begin(), s.variants.end(),
                         [&](const AblationVariant& v) { return v.name == name; });
    });
    if (!found)
      throw std::invalid_argument("--variants " + names + ": '" + name +
                                  "' is not a variant of the studies asked for (" + known + ")");
  }
  for (AblationStudy& s : studies)
    s.variants.erase(std::remove_if(s.variants.begin(), s.variants.end(),
                                    [&](const AblationVariant& v) {
                                      return std::find(wanted.begin(), wanted.end(), v.name) == wanted.end();
                                    }),
                     s.variants.end());
  studies.erase(std::remove_if(studies.begin(), studies.end(),
                               [](const AblationStudy& s) { return s.variants.empty(); }),
                studies.end());
  return studies;
}

std::string run_ablation(const AblateOptions& o, const std::string& command_line, std::ostream& out) {
  const std::vector<AblationStudy> studies = keep_variants(ablation_studies(o.study, o.config), o.variants);
  size_t total = 0, done = 0;
  for (const auto& s : studies) total += s.variants.size();
  std::string md = "Made by `" + command_line + "`.\n";
  json all = json::object();
  for (const AblationStudy& s : studies) {
    std::vector<json> records;
    for (const AblationVariant& v : s.variants) {
      out << "ablate: [" << ++done << "/" << total << "] " << s.name << ": " << v.name << "\n" << std::flush;
      RunOptions r{o.input,  o.out_dir, "",   v.until,
                   o.config, o.engine,  true, "runs/" + s.name + "-" + v.name};
      v.apply(r.config);
      try {
        records.push_back(run_pipeline(r, out));
      } catch (const StageFailed& e) {
        // A variant the scene cannot run (the true poses without gt/, say): its row says why, the
        // others still run.
        out << "ablate: " << s.name << ": " << v.name << ": " << e.what() << "; going on\n";
        records.push_back({{"failed", e.what()}});
      }
      all[s.name][v.name] = records.back();
    }
    md += "\n### " + s.name + "\n\n" + markdown_table(s, records);
    if (!s.note.empty()) md += "\n" + s.note + "\n";
  }
  io::write_file_atomic(o.out_dir / "ablation.md", [&](std::ostream& f) { f << md; });
  io::write_file_atomic(o.out_dir / "ablation.json", [&](std::ostream& f) { f << all.dump(2) << "\n"; });
  out << "ablate: tables in " << (o.out_dir / "ablation.md").string() << "\n" << md;
  return md;
}

}  // namespace litgs::host::run
