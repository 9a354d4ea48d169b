// The report's account of a budget grown inside the training (`train.max_gaussians: grow`), from
// metrics.json's budget_growth (host/train/budget_growth.h): where it started and ended, why it stopped, each
// phase's budget, size, validation PSNR, paired gain, training views' gain, seconds and decision; and the
// points of the two growth charts (validation PSNR against Gaussians and against seconds).
#pragma once

#include <nlohmann/json.hpp>
#include <string>

namespace litgs::host::run {

// HTML, escaped; `growth` is metrics.json's budget_growth. A record of the wrong shape gives a paragraph that
// says so. The charts' canvases (ids growth_gaussians and growth_time) come with it when a phase was scored.
std::string growth_section_html(const nlohmann::json& growth);

// The charts' points: [{gaussians, seconds, psnr_db, stop}] for each scored phase (stop: the phase whose
// decision stopped the growth), or null when none was scored or the record is damaged.
nlohmann::json growth_chart_json(const nlohmann::json& growth);

}  // namespace litgs::host::run
