// The report's "Budget" section: how the training's Gaussian budget was chosen, from DIR/train/budget.json
// (written by `train --max-gaussians search` or `auto`). For a search, each budget tried with its validation
// PSNR (the folds' mean and each fold's), the Gaussians reached, the seconds, and which budget was kept and
// why; for auto, the surface measurement it came from. A fixed budget has no budget.json: one line says so.
#pragma once

#include <nlohmann/json.hpp>
#include <string>

namespace litgs::host::run {

// `budget` is budget.json's content, or null when the file does not exist; a record of the wrong shape gives
// a paragraph that says so. HTML, escaped.
std::string budget_section_html(const nlohmann::json& budget, uint64_t gaussians_trained);

}  // namespace litgs::host::run
