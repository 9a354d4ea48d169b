// Exclusive scan on the device against a CPU scan: sizes 0, 1, subgroup +-1, block +-1, multi-level.
#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <vector>

#include "engine/buffer.h"
#include "engine/sequence.h"
#include "gpu_test.h"
#include "kernels/scan/scan.h"
#include "kernels/subgroup_kernel.h"

namespace litgs {
namespace {

class ScanTest : public testing::GpuTest {
 protected:
  // Scans `input` on the device with `options`; returns the result.
  std::vector<uint32_t> device_scan(const std::vector<uint32_t>& input, kernels::ScanOptions options = {}) {
    kernels::ExclusiveScan scan(context(), options);
    engine::DeviceArray<uint32_t> data(context(), "scan data", input.size());
    data.upload(input);
    engine::Sequence seq(context());
    scan.record(seq, data.buffer(), static_cast<uint32_t>(input.size()));
    seq.submit_and_wait();
    return data.download();
  }
};

std::vector<uint32_t> cpu_exclusive_scan(const std::vector<uint32_t>& in) {
  std::vector<uint32_t> out(in.size());
  uint32_t sum = 0;
  for (size_t i = 0; i < in.size(); ++i) {
    out[i] = sum;
    sum += in[i];  // wraps modulo 2^32 like the kernel
  }
  return out;
}

std::vector<uint32_t> random_values(size_t n, uint32_t max_value, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_int_distribution<uint32_t> dist(0, max_value);
  std::vector<uint32_t> v(n);
  for (auto& x : v) x = dist(rng);
  return v;
}

TEST_F(ScanTest, Sizes) {
  const uint32_t s = kernels::subgroup_width(context());
  const uint32_t block = kernels::ExclusiveScan(context()).block_size();
  for (size_t n : {size_t{0}, size_t{1}, size_t{s - 1}, size_t{s}, size_t{s + 1}, size_t{block - 1},
                   size_t{block}, size_t{block + 1}, size_t{65537}, size_t{1000003}}) {
    const auto input = random_values(n, 1000, static_cast<uint32_t>(n));
    EXPECT_EQ(device_scan(input), cpu_exclusive_scan(input)) << "n = " << n;
  }
}

TEST_F(ScanTest, MultiLevelWithSmallBlocks) {
  const uint32_t s = kernels::subgroup_width(context());
  kernels::ScanOptions options;
  options.block_size = 2 * s;
  kernels::ExclusiveScan probe(context(), options);
  // Three levels need more than block^3 elements: 4,096 with lavapipe's 8 lanes, 262,144 with 32 lanes.
  const size_t block = options.block_size;
  const size_t n = std::max<size_t>(100003, block * block * block + 3 * block + 1);
  EXPECT_GE(probe.levels(static_cast<uint32_t>(n)), 3u) << "the test should exercise several levels";
  const auto input = random_values(n, 7, 3);
  EXPECT_EQ(device_scan(input, options), cpu_exclusive_scan(input));
}

TEST_F(ScanTest, WrapsModulo2To32) {
  const std::vector<uint32_t> input(300, 0x40000000u);
  EXPECT_EQ(device_scan(input), cpu_exclusive_scan(input));
}

TEST_F(ScanTest, RejectsBlockSizeNotMultipleOfSubgroup) {
  kernels::ScanOptions options;
  options.block_size = kernels::subgroup_width(context()) + 1;
  EXPECT_THROW(kernels::ExclusiveScan(context(), options), std::invalid_argument);
}

TEST_F(ScanTest, RejectsBlockBeyondLoopCap) {
  kernels::ScanOptions options;
  options.block_size = kernels::subgroup_width(context()) * 40000;
  EXPECT_THROW(kernels::ExclusiveScan(context(), options), std::invalid_argument);
}

TEST_F(ScanTest, RejectsCountBeyondBuffer) {
  kernels::ExclusiveScan scan(context());
  engine::DeviceArray<uint32_t> data(context(), "short", 10);
  engine::Sequence seq(context());
  EXPECT_THROW(scan.record(seq, data.buffer(), 11), std::out_of_range);
}

}  // namespace
}  // namespace litgs
