// Runs the built litgs-engine binary (LITGS_ENGINE_BINARY, set by CMake) for the CLI tests.
#pragma once

#include <cstdio>
#include <string>

namespace litgs::testing {

struct CommandResult {
  int status;          // pclose's status: 0 when the command exited 0
  std::string output;  // stdout and stderr together
};

inline CommandResult run_engine(const std::string& args) {
  const std::string cmd = std::string(LITGS_ENGINE_BINARY) + " " + args + " 2>&1";
  CommandResult r{0, ""};
  FILE* pipe = popen(cmd.c_str(), "r");
  if (!pipe) return {-1, "popen failed: " + cmd};
  char buf[512];
  while (fgets(buf, sizeof buf, pipe)) r.output += buf;
  r.status = pclose(pipe);
  return r;
}

}  // namespace litgs::testing
