#include "io/atomic_file.h"

#include <unistd.h>

#include <atomic>
#include <fstream>
#include <system_error>

#include "io/error.h"

namespace litgs::io {
namespace {
std::atomic<unsigned> g_counter{0};
}

AtomicFile::AtomicFile(std::filesystem::path target) : target_(std::move(target)) {
  temp_ = target_;
  temp_ += ".tmp-" + std::to_string(::getpid()) + "-" + std::to_string(g_counter++);
}

AtomicFile::~AtomicFile() {
  if (!committed_) {
    std::error_code ec;
    std::filesystem::remove(temp_, ec);  // best effort: never throw from a destructor
  }
}

void AtomicFile::commit() {
  std::error_code ec;
  std::filesystem::rename(temp_, target_, ec);
  if (ec)
    fail(target_, 0, "cannot rename the temporary file " + temp_.string() + " onto it: " + ec.message());
  committed_ = true;
}

void write_file_atomic(const std::filesystem::path& target, const std::function<void(std::ostream&)>& write) {
  AtomicFile file(target);
  {
    std::ofstream out(file.temp_path(), std::ios::binary | std::ios::trunc);
    if (!out) fail(target, 0, "cannot open the temporary file " + file.temp_path().string() + " for writing");
    write(out);
    out.flush();
    if (!out) fail(target, 0, "write failed (disk full?)");
  }
  file.commit();
}

}  // namespace litgs::io
