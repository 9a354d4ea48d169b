// The one thread that does all device work of the service (renders and model uploads), with a bounded
// queue in front of it. Serialized on purpose: the engine drives one Vulkan queue, a Rasterizer owns its
// per-render buffers and is not thread-safe, and on lavapipe a single render already spreads over every CPU
// core; several device workers would multiply the render buffers' memory and contend for the same cores
// without rendering more per second. A full queue is refused at once (the HTTP layer answers 503), so
// overload never piles up.
#pragma once

#include <condition_variable>
#include <cstddef>
#include <deque>
#include <functional>
#include <mutex>
#include <thread>

namespace litgs::serve {

class DeviceWorker {
 public:
  // `setup` runs first on the device thread (it creates the Vulkan context there), `teardown` last.
  DeviceWorker(size_t max_queue, std::function<void()> setup, std::function<void()> teardown);
  ~DeviceWorker();  // stop()
  DeviceWorker(const DeviceWorker&) = delete;
  DeviceWorker& operator=(const DeviceWorker&) = delete;

  // Queues `job`; false (not queued) when max_queue jobs already wait or the worker is stopping.
  bool try_post(std::function<void()> job);
  // Jobs waiting, not counting the one running.
  size_t depth() const;
  // Runs the jobs already queued, then joins the thread. Idempotent.
  void stop();
  // Waits until `setup` has run; rethrows what it threw.
  void wait_ready();

 private:
  void run(std::function<void()> setup, std::function<void()> teardown);

  size_t max_queue_;
  mutable std::mutex mutex_;
  std::condition_variable changed_;
  std::deque<std::function<void()>> jobs_;
  bool stopping_ = false, ready_ = false;
  std::exception_ptr setup_error_;
  std::thread thread_;
};

}  // namespace litgs::serve
