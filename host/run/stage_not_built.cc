// Stages whose code is not on this branch yet (map, match, refine): listed so that every run reports them,
// as "skipped: not built yet", and never faked. Wiring one in replaces its row in stage_table.cc.
#include "host/run/stage.h"

namespace litgs::host::run {

Stage not_built_stage(const std::string& name, const std::string& what) {
  return {name, what, false, {}, {}};
}

}  // namespace litgs::host::run
