#include "host/run/stage.h"

namespace litgs::host::run {

const std::vector<Stage>& stage_table() {
  static const std::vector<Stage> table = {
      import_stage(), map_stage(), match_stage(), refine_stage(), train_stage(), eval_stage(), report_stage(),
  };
  return table;
}

}  // namespace litgs::host::run
