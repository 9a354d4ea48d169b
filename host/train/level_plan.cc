#include "host/train/level_plan.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <stdexcept>

#include "io/atomic_file.h"
#include "io/error.h"
#include "kernels/level/level_reference.h"

namespace litgs::host {

LevelModelKind parse_level_model(const std::string& name) {
  if (name == "none") return LevelModelKind::kNone;
  if (name == "affine") return LevelModelKind::kAffine;
  if (name == "affine-vignetting") return LevelModelKind::kAffineVignetting;
  throw std::invalid_argument("level model must be none, affine or affine-vignetting, not '" + name + "'");
}

LevelPlan::LevelPlan(const TrainingData& data) {
  const size_t n = data.views.size();
  segment.assign(n, 0);
  prev.assign(n, -1);
  next.assign(n, -1);
  for (size_t i = 1; i < n; ++i) segment[i] = segment[i - 1] + (data.views[i].after_frozen ? 1 : 0);
  for (const TrainingView& v : data.views) trained.push_back(!v.heldout);
  // Views are in time order (the scene's frames); neighbours are the nearest training views in the segment.
  int last = -1;
  for (uint32_t i = 0; i < n; ++i) {
    if (last >= 0 && segment[static_cast<size_t>(last)] != segment[i]) last = -1;
    prev[i] = last;
    if (!data.views[i].heldout) last = static_cast<int>(i);
  }
  last = -1;
  for (size_t k = n; k-- > 0;) {
    if (last >= 0 && segment[static_cast<size_t>(last)] != segment[k]) last = -1;
    next[k] = last;
    if (!data.views[k].heldout) last = static_cast<int>(k);
  }
}

kernels::LevelStep LevelPlan::step(uint32_t view, uint32_t it, const TrainOptions& o) const {
  kernels::LevelStep s;
  s.frame = view;
  s.prev = prev.at(view);
  s.next = next.at(view);
  const float decay = static_cast<float>(std::pow(0.1, static_cast<double>(it) / std::max(1u, o.iterations)));
  s.lr_log_gain = o.level_lr_log_gain * decay * o.lr_scale;
  s.lr_offset = o.level_lr_offset * decay * o.lr_scale;
  s.lr_vignetting = o.level_lr_vignetting * decay * o.lr_scale;
  s.lambda_identity = o.level_lambda_identity;
  s.lambda_smooth = o.level_lambda_smooth;
  return s;
}

kernels::LevelValues LevelTable::values(size_t i) const {
  const LevelEntry& e = entries.at(i);
  return {e.log_gain, e.offset, vignetting() ? k1 : 0.0, vignetting() ? k2 : 0.0};
}

namespace {
// Linear in time between the trained entries of `segment` around t (the nearer alone beyond them).
std::pair<double, double> interpolate(const std::vector<LevelEntry>& entries, uint32_t segment, double t) {
  const LevelEntry *before = nullptr, *after = nullptr;
  for (const LevelEntry& e : entries) {
    if (!e.trained || e.segment != segment) continue;
    if (e.t_s <= t && (!before || e.t_s >= before->t_s)) before = &e;
    if (e.t_s >= t && (!after || e.t_s < after->t_s)) after = &e;
  }
  if (!before && !after) return {0.0, 0.0};
  if (!before) return {after->log_gain, after->offset};
  if (!after || after->t_s == before->t_s) return {before->log_gain, before->offset};
  const double w = (t - before->t_s) / (after->t_s - before->t_s);
  return {(1 - w) * before->log_gain + w * after->log_gain, (1 - w) * before->offset + w * after->offset};
}
}  // namespace

kernels::LevelValues LevelTable::at_time(double t) const {
  if (entries.empty()) return {};
  const LevelEntry* nearest = &entries.front();
  for (const LevelEntry& e : entries)
    if (std::abs(e.t_s - t) < std::abs(nearest->t_s - t)) nearest = &e;
  const auto [lg, o] = interpolate(entries, nearest->segment, t);
  return {lg, o, vignetting() ? k1 : 0.0, vignetting() ? k2 : 0.0};
}

LevelTable make_level_table(const TrainingData& data, const LevelPlan& plan, LevelModelKind kind,
                            const std::vector<float>& state) {
  LevelTable t;
  t.model = kind == LevelModelKind::kNone     ? "none"
            : kind == LevelModelKind::kAffine ? "affine"
                                              : "affine-vignetting";
  t.stretch_low = data.stretch_low;
  t.stretch_high = data.stretch_high;
  const bool learned = kind != LevelModelKind::kNone && !state.empty();
  for (uint32_t i = 0; i < data.views.size(); ++i) {
    LevelEntry e;
    e.name = data.views[i].name;
    e.t_s = data.views[i].t_s;
    e.segment = plan.segment[i];
    e.trained = !data.views[i].heldout;
    if (learned && e.trained) {
      const kernels::LevelValues v = kernels::level_values(state, i, false);
      e.log_gain = v.log_gain;
      e.offset = v.offset;
    }
    t.entries.push_back(e);
  }
  for (LevelEntry& e : t.entries)
    if (!e.trained) std::tie(e.log_gain, e.offset) = interpolate(t.entries, e.segment, e.t_s);
  if (learned && t.vignetting()) {
    const kernels::LevelValues v = kernels::level_values(state, 0, true);
    t.k1 = v.k1;
    t.k2 = v.k2;
  }
  return t;
}

nlohmann::json to_json(const LevelTable& t) {
  nlohmann::json frames = nlohmann::json::array();
  for (const LevelEntry& e : t.entries)
    frames.push_back({{"name", e.name},
                      {"t_s", e.t_s},
                      {"segment", e.segment},
                      {"trained", e.trained},
                      {"log_gain", e.log_gain},
                      {"gain", std::exp(e.log_gain)},
                      {"offset", e.offset}});
  return {{"level_model", t.model},
          {"units",
           "x' = gain * v(r) * x + offset on stretched values x in [0, 1]; raw counts = stretch_low "
           "+ x * (stretch_high - stretch_low); v(r) = 1 + k1 r^2 + k2 r^4, r from the principal "
           "point over the half diagonal; the map's level is the trained frames' mean (mean "
           "log_gain 0, mean offset 0)"},
          {"stretch_low", t.stretch_low},
          {"stretch_high", t.stretch_high},
          {"vignetting_k1", t.k1},
          {"vignetting_k2", t.k2},
          {"frames", frames}};
}

void write_level_table(const std::filesystem::path& path, const LevelTable& table) {
  const nlohmann::json j = to_json(table);
  io::write_file_atomic(path, [&](std::ostream& out) { out << j.dump(2) << "\n"; });
}

LevelTable read_level_table(const std::filesystem::path& path) {
  std::ifstream in(path);
  if (!in) io::fail(path, 0, "cannot open the level table");
  LevelTable t;
  try {
    const nlohmann::json j = nlohmann::json::parse(in);
    t.model = j.at("level_model").get<std::string>();
    parse_level_model(t.model);
    t.stretch_low = j.at("stretch_low").get<double>();
    t.stretch_high = j.at("stretch_high").get<double>();
    t.k1 = j.at("vignetting_k1").get<double>();
    t.k2 = j.at("vignetting_k2").get<double>();
    for (const auto& f : j.at("frames")) {
      LevelEntry e;
      e.name = f.at("name").get<std::string>();
      e.t_s = f.at("t_s").get<double>();
      e.segment = f.at("segment").get<uint32_t>();
      e.trained = f.at("trained").get<bool>();
      e.log_gain = f.at("log_gain").get<double>();
      e.offset = f.at("offset").get<double>();
      if (!std::isfinite(e.t_s) || !std::isfinite(e.log_gain) || !std::isfinite(e.offset))
        throw std::invalid_argument("frame '" + e.name + "' has a non-finite value");
      t.entries.push_back(e);
    }
  } catch (const std::exception& e) {
    io::fail(path, 0, std::string("bad level table: ") + e.what());
  }
  if (!(t.stretch_high > t.stretch_low)) io::fail(path, 0, "stretch_high must exceed stretch_low");
  return t;
}

std::vector<float> apply_level(const std::vector<float>& image, const kernels::LevelGeometry& geometry,
                               const kernels::LevelValues& values, bool vignetting) {
  const std::vector<double> x = kernels::level_apply_reference(image, geometry, values, vignetting);
  return {x.begin(), x.end()};
}

}  // namespace litgs::host
