#include "host/run/report_growth.h"

#include <stdexcept>

#include "host/run/report_html.h"

namespace litgs::host::run {
namespace {

using nlohmann::json;

bool stopped_here(const json& phase) {
  return phase.value("decision", std::string()).rfind("stop", 0) == 0;
}

bool scored(const json& phase) {
  return phase.contains("validation_psnr_db") && phase.at("validation_psnr_db").is_number();
}

std::string gain_text(const json& phase) {
  if (!json_field(phase, "gain_db").is_number()) return "&ndash;";
  std::string text = number(json_field(phase, "gain_db"), 2);
  if (json_field(phase, "gain_se_db").is_number())
    text += " &plusmn; " + number(json_field(phase, "gain_se_db"), 2);
  return text;
}

std::string growth_html(const json& g) {
  const json& phases = g.at("phases");
  if (!phases.is_array()) throw std::invalid_argument("phases is not a list");
  std::string first = "&ndash;";
  for (const json& p : phases)
    if (p.contains("budget")) {
      first = std::to_string(p.at("budget").get<uint64_t>());
      break;
    }
  const std::string reason = g.value("stop_reason", std::string());
  const std::string last = std::to_string(g.at("budget").get<uint64_t>());
  std::string h =
      "<p>Grown inside the training (<code>max_gaussians: grow</code>): " +
      (phases.empty() ? "kept at its start, <b>" + last + "</b>"
                      : "from a budget of " + first + " to <b>" + last + "</b>") +
      " (ceiling " + std::to_string(g.value("ceiling", uint64_t{0})) + "). " +
      (reason.empty()
           ? std::string("Still growing when the training ended.")
           : "Stopped: " + escape_html(reason.rfind("stop: ", 0) == 0 ? reason.substr(6) : reason) + ".") +
      "</p>\n";
  if (!growth_chart_json(g).is_null())
    h += "<div class=charts><div class=chart><canvas id=growth_gaussians></canvas></div><div "
         "class=chart><canvas "
         "id=growth_time></canvas></div></div>\n";
  h += "<table class=budget><tr><th>iteration</th><th>budget</th><th>Gaussians</th><th>validation PSNR "
       "dB</th><th>gain dB</th><th>training views' gain dB</th><th>seconds</th><th>decision</th></tr>\n";
  for (const json& p : phases) {
    h += "<tr" + std::string(stopped_here(p) ? " class=kept" : "") + ">" +
         html_cell(std::to_string(p.value("iteration", 0))) +
         html_cell(std::to_string(p.value("budget", 0))) +
         html_cell(std::to_string(p.value("gaussians", 0))) +
         html_cell(number(json_field(p, "validation_psnr_db"), 2)) + html_cell(gain_text(p)) +
         html_cell(number(json_field(p, "training_gain_db"), 2)) +
         html_cell(number(json_field(p, "wall_s"), 1)) + "<td class=note>" +
         escape_html(p.value("decision", std::string())) + "</td></tr>\n";
  }
  return h + "</table>\n";
}

}  // namespace

json growth_chart_json(const json& growth) {
  try {
    json points = json::array();
    for (const json& p : growth.at("phases"))
      if (scored(p))
        points.push_back({{"gaussians", p.at("gaussians")},
                          {"seconds", p.at("wall_s")},
                          {"psnr_db", p.at("validation_psnr_db")},
                          {"stop", stopped_here(p)}});
    return points.empty() ? json() : points;
  } catch (const json::exception&) {
    return json();
  }
}

std::string growth_section_html(const json& growth) {
  try {
    if (!growth.is_object()) throw std::invalid_argument("not a JSON object");
    return growth_html(growth);
  } catch (const std::exception& e) {  // a damaged record costs its section, not the report
    return "<p>metrics.json's budget_growth is not a growth record (" + escape_html(e.what()) + ").</p>\n";
  }
}

}  // namespace litgs::host::run
