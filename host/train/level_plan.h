// The radiometric level model's place in training (kernels/level/): which kind, each view's neighbours in
// time for the smoothness term, an iteration's rates, and the level of any view or time, held-out views
// interpolated from the training views around them. The map's own level is the training frames' mean (their
// mean log-gain and mean offset are held at 0: kernels/level/level_shared.h).
//
// Segments: frames frozen by the camera's non-uniformity correction (NUC) are skipped, and the frame after
// them may jump in level; views between two such runs form a segment. Neighbours and interpolation stay
// within a segment, so the smoothness term does not fight the jump and a held-out view is never interpolated
// across it.
#pragma once

#include <cstdint>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "host/train/train_options.h"
#include "host/train/training_data.h"
#include "kernels/level/level_model.h"

namespace litgs::host {

enum class LevelModelKind { kNone, kAffine, kAffineVignetting };
// "none" | "affine" | "affine-vignetting"; std::invalid_argument naming the value otherwise.
LevelModelKind parse_level_model(const std::string& name);

struct LevelPlan {
  explicit LevelPlan(const TrainingData& data);
  std::vector<uint32_t> segment;  // per view
  std::vector<int> prev, next;    // per view: the nearest training view before / after it in its segment
  std::vector<bool> trained;      // per view: not held out
  // The step of iteration `it` on training view `view`: rates decay log-linearly to a tenth over the run.
  kernels::LevelStep step(uint32_t view, uint32_t it, const TrainOptions& options) const;
};

// One frame's level in levels.json: log-gain and offset in the stretched units training uses ([0, 1] over
// the stretch window); `trained` false: interpolated (a held-out view).
struct LevelEntry {
  std::string name;
  double t_s = 0;
  uint32_t segment = 0;
  bool trained = true;
  double log_gain = 0, offset = 0;
};

// What levels.json holds: the model, the stretch window (raw counts = low + x (high - low)), every view's
// level in time order, and the shared vignetting.
struct LevelTable {
  std::string model = "none";
  double stretch_low = 0, stretch_high = 1;
  double k1 = 0, k2 = 0;
  std::vector<LevelEntry> entries;
  bool vignetting() const { return model == "affine-vignetting"; }
  kernels::LevelValues values(size_t entry) const;
  // The level at time t: linear in time between the trained entries of the nearest entry's segment that
  // enclose t (the nearer one alone beyond them; identity if the segment has none).
  kernels::LevelValues at_time(double t_s) const;
};

// The table of a run: trained views from `state` (kernels::LevelModel's), held-out views interpolated. An
// empty state (level model none) gives identity everywhere.
LevelTable make_level_table(const TrainingData& data, const LevelPlan& plan, LevelModelKind kind,
                            const std::vector<float>& state);
nlohmann::json to_json(const LevelTable& table);
// Writes atomically; read_level_table throws io::IoError naming the file and the problem.
void write_level_table(const std::filesystem::path& path, const LevelTable& table);
LevelTable read_level_table(const std::filesystem::path& path);

// x' = g v x + o on the CPU for an image [channels][H][W] with the camera's principal point.
std::vector<float> apply_level(const std::vector<float>& image, const kernels::LevelGeometry& geometry,
                               const kernels::LevelValues& values, bool vignetting);

}  // namespace litgs::host
