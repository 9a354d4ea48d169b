// A small pool over independent jobs (images, pairs, tracks): the front end's one way to use the cores.
#pragma once

#include <cstddef>
#include <functional>

namespace litgs::host::frontend {

// Runs fn(0) .. fn(n - 1) on `threads` threads (0: all cores), each index once, in no set order. The first
// exception a job throws is rethrown here after every thread has stopped.
void parallel_for(size_t n, int threads, const std::function<void(size_t)>& fn);

// The threads to use for `requested` (0: all cores), at least 1.
int resolve_threads(int requested);

// While alive, OpenCV's own parallel loops run on one thread (the pool above already fills the cores).
class OpenCvSingleThread {
 public:
  OpenCvSingleThread();
  ~OpenCvSingleThread();
  OpenCvSingleThread(const OpenCvSingleThread&) = delete;
  OpenCvSingleThread& operator=(const OpenCvSingleThread&) = delete;

 private:
  int previous_;
};

}  // namespace litgs::host::frontend
