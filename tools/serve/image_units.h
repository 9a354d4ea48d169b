// The data units of a model's image channel: train maps the raw frame values onto [0, 1] through a stretch
// window and writes it to levels.json beside the model; the viewer shows legends and cursor values in the
// raw units through it (raw = low + x (high - low)).
#pragma once

#include <filesystem>
#include <optional>
#include <string>

namespace litgs::serve {

struct ImageUnits {
  std::string name = "raw counts";  // the training frames' values (16-bit counts or 8-bit grey levels)
  double low = 0, high = 1;         // the raw values of model intensity 0 and 1
  std::string source;               // the levels.json they came from
};

// `explicit_levels` when given (a missing or malformed file throws, naming it), else levels.json beside
// `model` when it exists there (a symlink leading out of the model's folder is ignored), else none: the
// model's own units [0, 1].
std::optional<ImageUnits> find_image_units(const std::filesystem::path& model,
                                           const std::string& explicit_levels);

}  // namespace litgs::serve
