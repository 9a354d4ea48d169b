// Runs a stage's command as a child process: its output goes to the terminal and to the stage's log, and its
// peak memory comes from the kernel's accounting of the child (wait4's ru_maxrss).
#pragma once

#include <cstdint>
#include <filesystem>
#include <ostream>
#include <string>
#include <vector>

namespace litgs::host::run {

struct ChildResult {
  int exit_code = -1;  // -1 when killed by a signal
  int signal = 0;
  double seconds = 0;
  uint64_t peak_host_bytes = 0;
  std::string tail;  // the last lines of its output (stdout and stderr), for a failure's message
};

// `program args...`; output echoed to `echo` and appended to `log`. The child is killed when this process
// dies (PR_SET_PDEATHSIG), so that a killed run leaves no orphan writing into DIR. Throws std::runtime_error
// when the child cannot be started.
ChildResult run_child(const std::filesystem::path& program, const std::vector<std::string>& args,
                      const std::filesystem::path& log, std::ostream& echo);

}  // namespace litgs::host::run
