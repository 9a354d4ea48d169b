#include "tools/serve/image_units.h"

#include "host/train/level_plan.h"

namespace litgs::serve {

namespace fs = std::filesystem;

namespace {

ImageUnits units_from(const fs::path& levels) {
  const host::LevelTable table = host::read_level_table(levels);  // io::IoError naming the file
  ImageUnits u;
  u.low = table.stretch_low;
  u.high = table.stretch_high;
  u.source = levels.string();
  return u;
}

}  // namespace

std::optional<ImageUnits> find_image_units(const fs::path& model, const std::string& explicit_levels) {
  if (!explicit_levels.empty()) return units_from(explicit_levels);
  const fs::path beside = model.parent_path() / "levels.json";
  std::error_code ec;
  if (!fs::is_regular_file(beside, ec)) return std::nullopt;
  // Models loaded over HTTP are confined to --models-dir: so is the file read beside them.
  if (fs::canonical(beside, ec).parent_path() !=
      fs::canonical(model.parent_path().empty() ? "." : model.parent_path(), ec))
    return std::nullopt;
  return units_from(beside);
}

}  // namespace litgs::serve
