// Regressions found by the libFuzzer target tests/fuzz/fuzz_checkpoint.cc: each input in
// tests/fuzz/regressions/checkpoint-* must be rejected with io::IoError (and, under ci/fuzz's sanitizers,
// without undefined behaviour).
#include <gtest/gtest.h>

#include <filesystem>

#include "host/train/checkpoint.h"
#include "io/error.h"

namespace litgs::host {
namespace {

const std::filesystem::path kRegressions = LITGS_FUZZ_REGRESSIONS_DIR;

// An empty array (view order) before a truncated one: Reader::get_vector passed the empty vector's null
// data() to memcpy (UBSan: null pointer passed as argument declared nonnull).
TEST(CheckpointFuzzRegression, EmptyArrayThenTruncated) {
  EXPECT_THROW(read_checkpoint(kRegressions / "checkpoint-empty-array.ckpt"), io::IoError);
}

}  // namespace
}  // namespace litgs::host
