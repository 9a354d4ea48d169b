// A `litgs-engine serve` child process on an ephemeral loopback port, for `bench serve` and the HTTP tests:
// started with --host 127.0.0.1 --port 0, its port read from the "listening on" line it prints.
#pragma once

#include <sys/types.h>

#include <atomic>
#include <cstdint>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

namespace litgs::serve {

class ServerProcess {
 public:
  // Starts `binary serve --host 127.0.0.1 --port 0 ARGS...`; std::runtime_error with its output if it exits
  // or prints no port within `timeout_s`.
  ServerProcess(const std::string& binary, const std::vector<std::string>& args, double timeout_s = 120);
  ~ServerProcess();  // SIGKILL if it is still running
  ServerProcess(const ServerProcess&) = delete;
  ServerProcess& operator=(const ServerProcess&) = delete;

  int port() const { return port_; }
  pid_t pid() const { return pid_; }
  std::string output() const;  // stdout and stderr so far
  // Sends `signal`, waits up to timeout_s; the exit code, 128 + the signal if it died of one, -1 if it did
  // not end (then it is killed).
  int stop(int signal, double timeout_s = 60);
  // Resident memory (VmRSS of /proc/PID/status), 0 if unknown.
  uint64_t resident_bytes() const;

 private:
  pid_t pid_ = -1;
  int port_ = 0;
  int pipe_fd_ = -1;
  mutable std::mutex mutex_;
  std::string output_;
  std::thread reader_;
  bool reaped_ = false;
  int status_ = -1;
};

}  // namespace litgs::serve
