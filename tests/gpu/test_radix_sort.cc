// Stable key-value radix sort on the device against std::stable_sort. Values are the input positions, so
// comparing values checks stability.
#include <gtest/gtest.h>

#include <algorithm>
#include <numeric>
#include <random>
#include <string>
#include <vector>

#include "engine/buffer.h"
#include "engine/sequence.h"
#include "gpu_test.h"
#include "kernels/sort/radix_sort.h"
#include "kernels/subgroup_kernel.h"

namespace litgs {
namespace {

struct Pairs {
  std::vector<uint32_t> keys;
  std::vector<uint32_t> values;
};

// std::stable_sort on the low `bits` bits of the key.
Pairs reference_sort(const std::vector<uint32_t>& keys, uint32_t bits) {
  const uint32_t mask = bits >= 32 ? 0xFFFFFFFFu : (1u << bits) - 1u;
  std::vector<uint32_t> order(keys.size());
  std::iota(order.begin(), order.end(), 0u);
  std::stable_sort(order.begin(), order.end(),
                   [&](uint32_t a, uint32_t b) { return (keys[a] & mask) < (keys[b] & mask); });
  Pairs out;
  for (uint32_t i : order) {
    out.keys.push_back(keys[i]);
    out.values.push_back(i);
  }
  return out;
}

class RadixSortTest : public testing::GpuTest {
 protected:
  Pairs device_sort(const std::vector<uint32_t>& keys, uint32_t bits,
                    kernels::RadixSortOptions options = {}) {
    kernels::RadixSort sort(context(), options);
    std::vector<uint32_t> values(keys.size());
    std::iota(values.begin(), values.end(), 0u);
    engine::DeviceArray<uint32_t> d_keys(context(), "keys", keys.size()),
        d_values(context(), "values", keys.size());
    d_keys.upload(keys);
    d_values.upload(values);
    engine::Sequence seq(context());
    sort.record(seq, d_keys, d_values, static_cast<uint32_t>(keys.size()), bits);
    seq.submit_and_wait();
    return {d_keys.download(), d_values.download()};
  }

  void expect_sorted_like_std(const std::vector<uint32_t>& keys, uint32_t bits, const std::string& what,
                              kernels::RadixSortOptions options = {}) {
    const Pairs got = device_sort(keys, bits, options);
    const Pairs want = reference_sort(keys, bits);
    ASSERT_EQ(got.keys.size(), want.keys.size()) << what;
    size_t first_bad = got.keys.size();
    for (size_t i = 0; i < got.keys.size(); ++i)
      if (got.keys[i] != want.keys[i] || got.values[i] != want.values[i]) {
        first_bad = i;
        break;
      }
    EXPECT_EQ(first_bad, got.keys.size())
        << what << ": first difference at " << first_bad << " of " << keys.size() << " (bits " << bits << ")";
  }
};

std::vector<uint32_t> random_keys(size_t n, uint32_t seed, uint32_t mask = 0xFFFFFFFFu) {
  std::mt19937 rng(seed);
  std::vector<uint32_t> k(n);
  for (auto& x : k) x = static_cast<uint32_t>(rng()) & mask;
  return k;
}

const std::vector<size_t> kSizes = {0, 1, 7, 255, 256, 257, 65537, 1000003};

TEST_F(RadixSortTest, RandomKeys) {
  for (size_t n : kSizes)
    expect_sorted_like_std(random_keys(n, static_cast<uint32_t>(n) + 1), 32, "random n=" + std::to_string(n));
}

TEST_F(RadixSortTest, AllKeysEqual) {
  for (size_t n : kSizes)
    expect_sorted_like_std(std::vector<uint32_t>(n, 42u), 32, "equal n=" + std::to_string(n));
}

TEST_F(RadixSortTest, AlreadySorted) {
  for (size_t n : kSizes) {
    auto keys = random_keys(n, 5);
    std::sort(keys.begin(), keys.end());
    expect_sorted_like_std(keys, 32, "sorted n=" + std::to_string(n));
  }
}

TEST_F(RadixSortTest, ReverseSorted) {
  for (size_t n : kSizes) {
    auto keys = random_keys(n, 6);
    std::sort(keys.begin(), keys.end(), std::greater<>());
    expect_sorted_like_std(keys, 32, "reverse n=" + std::to_string(n));
  }
}

TEST_F(RadixSortTest, FewLowBitsUsedManyDuplicates) {
  // Keys in 0..15: long runs of equal keys, stability matters everywhere.
  for (size_t n : kSizes)
    expect_sorted_like_std(random_keys(n, 7, 0xFu), 32, "4-bit keys n=" + std::to_string(n));
}

TEST_F(RadixSortTest, MaxKeys) {
  for (size_t n : kSizes) {
    auto keys = random_keys(n, 8);
    for (size_t i = 0; i < n; i += 3) keys[i] = 0xFFFFFFFFu;
    expect_sorted_like_std(keys, 32, "0xFFFFFFFF n=" + std::to_string(n));
  }
}

TEST_F(RadixSortTest, LowBitsOnlyIgnoresHighBits) {
  // The tile pass of the splatting sort: sort on the low B bits, keep the order of the rest.
  for (uint32_t bits : {1u, 5u, 8u, 12u, 16u, 20u, 31u}) {
    expect_sorted_like_std(random_keys(65537, bits), bits, "bits=" + std::to_string(bits));
    expect_sorted_like_std(random_keys(1000003, bits + 100), bits, "bits=" + std::to_string(bits) + " large");
  }
}

TEST_F(RadixSortTest, ManyBlocksAndOneBlock) {
  kernels::RadixSortOptions one;
  one.max_blocks = 1;
  expect_sorted_like_std(random_keys(70001, 9), 32, "one block", one);
  kernels::RadixSortOptions many;
  many.max_blocks = 4096;
  many.min_batches_per_block = 1;
  expect_sorted_like_std(random_keys(300007, 10), 32, "many small blocks", many);
}

TEST_F(RadixSortTest, OneBlockRequestBeyondLoopCapStillSorts) {
  // lavapipe silently stops an invocation after 65535 loop iterations; a single block of 600k pairs would
  // need 75k batches at subgroup size 8. The layout must split it whatever max_blocks says.
  kernels::RadixSortOptions one;
  one.max_blocks = 1;
  kernels::RadixSort probe(context(), one);
  const auto layout = probe.layout(600000);
  EXPECT_LE(layout.block_size / kernels::subgroup_width(context()), 32768u);
  expect_sorted_like_std(random_keys(600000, 14), 32, "600k pairs, max_blocks 1", one);
}

TEST_F(RadixSortTest, ZeroBitsLeavesInputAlone) {
  const auto keys = random_keys(1000, 11);
  const Pairs got = device_sort(keys, 0);
  EXPECT_EQ(got.keys, keys);
}

TEST_F(RadixSortTest, RejectsBadArguments) {
  kernels::RadixSort sort(context());
  engine::DeviceArray<uint32_t> k(context(), "k", 10), v(context(), "v", 8);
  engine::Sequence seq(context());
  EXPECT_THROW(sort.record(seq, k, v, 10, 32), std::out_of_range) << "values shorter than count";
  EXPECT_THROW(sort.record(seq, k, k, 5, 33), std::invalid_argument) << "more than 32 bits";
}

TEST_F(RadixSortTest, SortsTwiceInOneSequence) {
  // Two sorts recorded back to back share scratch; the sequence's barriers must keep them apart.
  kernels::RadixSort sort(context());
  const auto a = random_keys(5000, 12), b = random_keys(7000, 13);
  std::vector<uint32_t> va(a.size()), vb(b.size());
  std::iota(va.begin(), va.end(), 0u);
  std::iota(vb.begin(), vb.end(), 0u);
  engine::DeviceArray<uint32_t> ka(context(), "ka", a.size()), kb(context(), "kb", b.size());
  engine::DeviceArray<uint32_t> da(context(), "va", a.size()), db(context(), "vb", b.size());
  ka.upload(a), kb.upload(b), da.upload(va), db.upload(vb);
  engine::Sequence seq(context());
  sort.record(seq, ka, da, static_cast<uint32_t>(a.size()), 32);
  sort.record(seq, kb, db, static_cast<uint32_t>(b.size()), 32);
  seq.submit_and_wait();
  EXPECT_EQ(ka.download(), reference_sort(a, 32).keys);
  EXPECT_EQ(db.download(), reference_sort(b, 32).values);
}

}  // namespace
}  // namespace litgs
