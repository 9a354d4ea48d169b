#include <cstdio>

#include "host/run/stage.h"

namespace litgs::host::run {

std::string number_arg(double value) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.17g", value);
  return buf;
}

const std::vector<Stage>& stage_table() {
  static const std::vector<Stage> table = {
      import_stage(),
      not_built_stage("map", "LiDAR map and planes (issue 14)"),
      not_built_stage("match", "thermal front end: contrast, features, matches (issue 13)"),
      not_built_stage("refine", "LiDAR-plane bundle adjustment of poses and anchors (issue 14)"),
      train_stage(),
      eval_stage(),
      report_stage(),
  };
  return table;
}

}  // namespace litgs::host::run
