#include "host/run/report_budget.h"

#include <stdexcept>

#include "host/run/report_html.h"

namespace litgs::host::run {
namespace {

using nlohmann::json;

std::string search_html(const json& b) {
  const uint64_t kept = b.value("gaussians", uint64_t{0});
  std::string h = "<p>Searched (<code>max_gaussians: search</code>): " + std::to_string(b.value("folds", 0)) +
                  " trainings per budget on the training views less a validation subset each; kept <b>" +
                  std::to_string(kept) +
                  "</b>, the last budget whose validation PSNR rose above the best before it";
  if (b.value("min_gain_db", 0.0) > 0) h += " by at least " + number(json_field(b, "min_gain_db"), 2) + " dB";
  if (b.value("parsimony_se", 0.0) > 0)
    h += " (with parsimony " + number(json_field(b, "parsimony_se"), 1) +
         " SE: the smallest within that of " + std::to_string(b.value("reference", 0)) + ")";
  h += ".</p>\n<table class=budget><tr><th>budget</th><th>validation PSNR dB</th><th>per fold</th>"
       "<th>Gaussians</th><th>seconds</th><th></th></tr>\n";
  for (const json& t : b.value("trials", json::array())) {
    const uint64_t budget = t.value("budget", uint64_t{0});
    h += "<tr" + std::string(budget == kept ? " class=kept" : "") + ">" + html_cell(std::to_string(budget));
    if (t.contains("failure")) {
      h += html_cell("&ndash;") + html_cell("") + html_cell("") + html_cell("") +
           html_cell("does not fit the device");
    } else {
      std::string folds;
      for (const json& f : t.value("validation_psnr_db_per_fold", json::array()))
        folds += (folds.empty() ? "" : " / ") + number(f, 2);
      std::string note = budget == kept ? "kept" : "";
      const auto add = [&](const char* why) { note += std::string(note.empty() ? "" : "; ") + why; };
      if (t.value("initial_gaussians", uint64_t{0}) >= budget) add("filled by its initialization");
      if (t.value("gaussians", budget) < budget)
        add("training did not fill it: a larger budget would not differ");
      h += html_cell(number(json_field(t, "validation_psnr_db"), 2)) + html_cell(folds) +
           html_cell(std::to_string(t.value("gaussians", 0))) +
           html_cell(number(json_field(t, "wall_s"), 1)) + html_cell(note);
    }
    h += "</tr>\n";
  }
  return h + "</table>\n";
}

std::string derived_html(const json& b) {
  return "<p>Derived from the scene (<code>max_gaussians: auto</code>): <b>" +
         std::to_string(b.value("gaussians", 0)) + "</b> Gaussians from " +
         std::to_string(b.value("points_seen", 0)) + " of " + std::to_string(b.value("points", 0)) +
         " points seen (" + escape_html(b.value("source", std::string("points"))) + "), " +
         number(json_field(b, "surface_m2"), 1) + " m<sup>2</sup> of surface, " +
         number(json_field(b, "surface_pixels"), 0) + " pixels at the finest view, " +
         number(json_field(b, "pixels_per_gaussian"), 1) + " pixels per Gaussian.</p>\n";
}

}  // namespace

std::string budget_section_html(const json& budget, uint64_t gaussians_trained) {
  if (budget.is_null())
    return "<p>A fixed budget (<code>train.max_gaussians</code>); the model has " +
           std::to_string(gaussians_trained) + " Gaussians.</p>\n";
  try {
    if (!budget.is_object()) throw std::invalid_argument("not a JSON object");
    if (budget.value("source", "") == "search") return search_html(budget);
    return derived_html(budget);
  } catch (const std::exception& e) {  // a damaged record costs its section, not the report
    return "<p>train/budget.json is not a budget record (" + escape_html(e.what()) + ").</p>\n";
  }
}

}  // namespace litgs::host::run
