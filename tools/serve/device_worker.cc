#include "tools/serve/device_worker.h"

namespace litgs::serve {

DeviceWorker::DeviceWorker(size_t max_queue, std::function<void()> setup, std::function<void()> teardown)
    : max_queue_(max_queue) {
  thread_ = std::thread([this, setup = std::move(setup), teardown = std::move(teardown)]() mutable {
    run(std::move(setup), std::move(teardown));
  });
}

DeviceWorker::~DeviceWorker() {
  stop();
}

void DeviceWorker::run(std::function<void()> setup, std::function<void()> teardown) {
  try {
    setup();
  } catch (...) {
    std::lock_guard lock(mutex_);
    setup_error_ = std::current_exception();
    ready_ = stopping_ = true;
    changed_.notify_all();
    return;
  }
  {
    std::lock_guard lock(mutex_);
    ready_ = true;
  }
  changed_.notify_all();
  for (;;) {
    std::function<void()> job;
    {
      std::unique_lock lock(mutex_);
      changed_.wait(lock, [&] { return stopping_ || !jobs_.empty(); });
      if (jobs_.empty()) break;  // stopping, and nothing left
      job = std::move(jobs_.front());
      jobs_.pop_front();
    }
    job();  // jobs catch their own exceptions and report through their promise
  }
  teardown();
}

bool DeviceWorker::try_post(std::function<void()> job) {
  {
    std::lock_guard lock(mutex_);
    if (stopping_ || jobs_.size() >= max_queue_) return false;
    jobs_.push_back(std::move(job));
  }
  changed_.notify_all();
  return true;
}

size_t DeviceWorker::depth() const {
  std::lock_guard lock(mutex_);
  return jobs_.size();
}

void DeviceWorker::wait_ready() {
  std::unique_lock lock(mutex_);
  changed_.wait(lock, [&] { return ready_; });
  if (setup_error_) std::rethrow_exception(setup_error_);
}

void DeviceWorker::stop() {
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
  }
  changed_.notify_all();
  if (thread_.joinable()) thread_.join();
}

}  // namespace litgs::serve
