// The engine's contracts: buffers, limits, binding checks and barrier placement.
#include <gtest/gtest.h>

#include <numeric>
#include <vector>

#include "engine/buffer.h"
#include "engine/sequence.h"
#include "engine/vk_check.h"
#include "gpu_test.h"
#include "kernels/bench/gather_bench.h"
#include "kernels/scan/scan_shared.h"
#include "kernels/spirv_registry.h"
#include "kernels/subgroup_kernel.h"

namespace litgs {
namespace {

using engine::Access;
using testing::GpuTest;

class EngineTest : public GpuTest {};

TEST_F(EngineTest, ReportsDeviceFacts) {
  const auto& info = context().info();
  EXPECT_FALSE(info.name.empty());
  EXPECT_GE(info.subgroup_size, 1u);
  EXPECT_EQ(info.subgroup_size & (info.subgroup_size - 1), 0u) << "subgroup size is a power of two";
  EXPECT_GT(info.max_storage_buffer_range, 0u);
  EXPECT_FALSE(info.memory_heaps.empty());
}

TEST_F(EngineTest, UploadDownloadRoundTrips) {
  std::vector<uint32_t> data(1000);
  std::iota(data.begin(), data.end(), 7u);
  engine::DeviceArray<uint32_t> device(context(), "roundtrip", data.size());
  device.upload(data);
  EXPECT_EQ(device.download(), data);
  EXPECT_EQ(device.download(10, 3), (std::vector<uint32_t>{17, 18, 19}));
}

TEST_F(EngineTest, HostVisibleBufferRoundTrips) {
  std::vector<float> data = {1.5f, -2.0f, 3.25f};
  engine::DeviceArray<float> device(context(), "host visible", data.size(), engine::MemoryKind::kHostVisible);
  device.upload(data);
  EXPECT_EQ(device.download(), data);
}

// Transfers to memory the host cannot map go through staging: the context's kept staging buffer up to
// kKeptStagingBytes (reused, grown when needed), a temporary one beyond. Both directions, at offsets, and
// sizes on either side of the limit.
TEST_F(EngineTest, UnmappedBuffersRoundTripThroughKeptAndTemporaryStaging) {
  const size_t kept_floats = engine::Context::kKeptStagingBytes / sizeof(float);
  for (size_t n : {size_t{3}, size_t{300000}, kept_floats, kept_floats + 1}) {
    std::vector<float> data(n);
    for (size_t i = 0; i < n; ++i) data[i] = static_cast<float>(i % 1000) * 0.5f - 7.0f;
    engine::DeviceArray<float> device(context(), "device only", n, engine::MemoryKind::kDeviceOnly);
    device.upload(data);
    EXPECT_EQ(device.download(), data) << n << " floats";
    if (n > 2) {
      EXPECT_EQ(device.download(1, 2), std::vector<float>(data.begin() + 1, data.begin() + 3));
    }
  }
  EXPECT_EQ(context().kept_staging_bytes(), engine::Context::kKeptStagingBytes)
      << "the kept staging buffer grows to the largest transfer within the limit and stays";
}

TEST_F(EngineTest, EmptyBufferIsValid) {
  engine::DeviceArray<uint32_t> empty(context(), "empty", 0);
  EXPECT_EQ(empty.size(), 0u);
  EXPECT_TRUE(empty.download().empty());
}

// peak_breakdown() is the buffers alive at the peak, by name: a later, smaller allocation leaves it as it
// was; a new peak replaces it, without what was released before.
TEST_F(EngineTest, PeakBreakdownNamesTheBuffersAliveAtThePeak) {
  auto bytes_of = [](const std::string& name) {
    for (const auto& [n, b] : engine::Buffer::peak_breakdown())
      if (n == name) return b;
    return uint64_t{0};
  };
  constexpr uint64_t kMiB = 1 << 20;
  // Over the process's peak so far (other tests of this binary may have set it), in chunks the device takes.
  auto allocate_past_peak = [&](const std::string& name) {
    const uint64_t target = engine::Buffer::peak_bytes();  // the peak rises with every allocation below
    std::vector<engine::Buffer> chunks;
    while (engine::Buffer::live_bytes() <= target)
      chunks.emplace_back(context(), name,
                          std::min<uint64_t>(64 * kMiB, target - engine::Buffer::live_bytes() + kMiB));
    return chunks;
  };
  {
    const std::vector<engine::Buffer> first = allocate_past_peak("test: first peak");
    EXPECT_GE(bytes_of("test: first peak"), kMiB);
    EXPECT_EQ(engine::Buffer::peak_breakdown().front().first, "test: first peak");
  }
  engine::Buffer small(context(), "test: below the peak", 4096);
  EXPECT_EQ(bytes_of("test: below the peak"), 0u) << "no new peak, no new snapshot";
  EXPECT_GE(bytes_of("test: first peak"), kMiB);
  const std::vector<engine::Buffer> second = allocate_past_peak("test: second peak");
  EXPECT_GE(bytes_of("test: second peak"), kMiB);
  EXPECT_EQ(bytes_of("test: first peak"), 0u) << "released before the new peak";
  EXPECT_GE(bytes_of("test: below the peak"), 4096u);
  uint64_t sum = 0;
  for (const auto& [name, b] : engine::Buffer::peak_breakdown()) sum += b;
  EXPECT_EQ(sum, engine::Buffer::peak_bytes());
}

TEST_F(EngineTest, OversizedBufferNamesBufferAndLimit) {
  const uint64_t too_big = context().info().max_storage_buffer_range + 4;
  try {
    engine::Buffer b(context(), "gaussian means", too_big);
    FAIL() << "expected std::length_error";
  } catch (const std::length_error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("gaussian means"), std::string::npos) << what;
    EXPECT_NE(what.find("maxStorageBufferRange"), std::string::npos) << what;
  }
}

TEST_F(EngineTest, OutOfRangeUploadIsRejected) {
  engine::DeviceArray<uint32_t> small(context(), "small", 4);
  std::vector<uint32_t> five(5, 1u);
  EXPECT_THROW(small.upload(five), std::out_of_range);
}

TEST_F(EngineTest, UnknownShaderIsNamed) {
  try {
    kernels::spirv("no/such_kernel");
    FAIL();
  } catch (const std::out_of_range& e) {
    EXPECT_NE(std::string(e.what()).find("no/such_kernel"), std::string::npos);
  }
}

TEST_F(EngineTest, DispatchChecksBindingsAndPushConstants) {
  auto kernel = kernels::make_subgroup_kernel(context(), "scan/scan_downsweep", SCAN_DOWNSWEEP_BINDING_COUNT,
                                              sizeof(kernels::ScanParams));
  engine::DeviceArray<uint32_t> a(context(), "a", 16);
  engine::Sequence seq(context());
  kernels::ScanParams params{16, 16, 0, 0};
  // Missing binding 1.
  EXPECT_THROW(seq.dispatch(*kernel, {1}, {{0, &a.buffer(), Access::kReadWrite}}, params),
               std::invalid_argument);
  // Repeated binding 0.
  EXPECT_THROW(seq.dispatch(*kernel, {1},
                            {{0, &a.buffer(), Access::kReadWrite}, {0, &a.buffer(), Access::kRead}}, params),
               std::invalid_argument);
  // Wrong push-constant size.
  const uint32_t wrong = 0;
  EXPECT_THROW(seq.dispatch(*kernel, {1},
                            {{0, &a.buffer(), Access::kReadWrite}, {1, &a.buffer(), Access::kRead}}, wrong),
               std::invalid_argument);
}

TEST_F(EngineTest, BarriersOnlyWhereHazardsAre) {
  auto kernel = kernels::make_subgroup_kernel(context(), "scan/scan_downsweep", SCAN_DOWNSWEEP_BINDING_COUNT,
                                              sizeof(kernels::ScanParams));
  engine::DeviceArray<uint32_t> a(context(), "a", 64), b(context(), "b", 64),
      offsets(context(), "offsets", 1);
  std::vector<uint32_t> ones(64, 1u);
  a.upload(ones);
  b.upload(ones);
  engine::Sequence seq(context());
  kernels::ScanParams params{64, 64, 0, 0};
  // Independent buffers: no barrier between the two scans.
  seq.dispatch(*kernel, {1}, {{0, &a.buffer(), Access::kReadWrite}, {1, &offsets.buffer(), Access::kRead}},
               params);
  seq.dispatch(*kernel, {1}, {{0, &b.buffer(), Access::kReadWrite}, {1, &offsets.buffer(), Access::kRead}},
               params);
  EXPECT_EQ(seq.barrier_count(), 0u);
  // Copy a into b after both were written: one barrier.
  seq.copy(a.buffer(), b.buffer(), 64 * sizeof(uint32_t));
  EXPECT_EQ(seq.barrier_count(), 1u);
  seq.submit_and_wait();
  std::vector<uint32_t> expected(64);
  std::iota(expected.begin(), expected.end(), 0u);
  EXPECT_EQ(b.download(), expected);
  const auto profile = seq.profile();
  if (context().info().timestamps) {
    ASSERT_EQ(profile.size(), 1u);
    EXPECT_EQ(profile[0].name, "scan/scan_downsweep");
    EXPECT_EQ(profile[0].dispatches, 2u);
    EXPECT_GE(profile[0].ms, 0.0);
  }
}

TEST_F(EngineTest, SequenceReplays) {
  auto kernel = kernels::make_subgroup_kernel(context(), "scan/scan_downsweep", SCAN_DOWNSWEEP_BINDING_COUNT,
                                              sizeof(kernels::ScanParams));
  engine::DeviceArray<uint32_t> a(context(), "a", 8), offsets(context(), "offsets", 1);
  engine::Sequence seq(context());
  seq.dispatch(*kernel, {1}, {{0, &a.buffer(), Access::kReadWrite}, {1, &offsets.buffer(), Access::kRead}},
               kernels::ScanParams{8, 8, 0, 0});
  for (uint32_t round = 1; round <= 2; ++round) {
    a.upload(std::vector<uint32_t>(8, round));
    seq.submit_and_wait();
    EXPECT_EQ(a.download()[7], 7u * round);
  }
  EXPECT_THROW(seq.fill(a.buffer(), 0u, 32), std::logic_error) << "recording after submit needs reset()";
  seq.reset();
  seq.fill(a.buffer(), 5u, 32);
  seq.submit_and_wait();
  EXPECT_EQ(a.download(), std::vector<uint32_t>(8, 5u));
}

// The three ways of reading records (storage floats, storage vec4, texel fetches) return the same sums, equal
// to the reference: a texel binding reads the buffer it is given, element by element.
TEST_F(EngineTest, TexelReadsReturnWhatTheBufferHolds) {
  const kernels::GatherBenchParams params{1001, 37};  // not a power of two: indices wrap unevenly
  const uint32_t invocations = 2 * GATHER_BENCH_GROUP_SIZE;
  std::vector<float> records(size_t{params.records} * 4);
  for (size_t k = 0; k < records.size(); ++k) records[k] = static_cast<float>((k * 7) % 97) - 40.0f;
  engine::DeviceArray<float> d_records(context(), "records", records.size());
  d_records.upload(records);
  const std::vector<double> expected = kernels::gather_bench_reference(records, invocations, params);
  for (auto read : {kernels::GatherRead::kStorageFloats, kernels::GatherRead::kStorageVec4,
                    kernels::GatherRead::kTexelVec4}) {
    engine::DeviceArray<float> sums(context(), "sums", size_t{invocations} * 4);
    kernels::GatherBench bench(context(), read);
    engine::Sequence seq(context());
    bench.record(seq, d_records, sums, params);
    seq.submit_and_wait();
    const std::vector<float> got = sums.download();
    for (size_t k = 0; k < got.size(); ++k)
      ASSERT_EQ(static_cast<double>(got[k]), expected[k])
          << kernels::gather_read_name(read) << ", value " << k;
  }
}

// The gather benchmark's texel kernel with the given texel bindings.
std::unique_ptr<engine::Kernel> gather_texel_kernel(engine::Context& context,
                                                    std::vector<engine::TexelBinding> texels) {
  return kernels::make_kernel(context, "bench/gather_texel", GATHER_BENCH_BINDING_COUNT,
                              sizeof(kernels::GatherBenchParams), {}, std::move(texels));
}

TEST_F(EngineTest, TexelBindingsAreCheckedWhenTheKernelIsBuilt) {
  const VkFormat rgba = VK_FORMAT_R32G32B32A32_SFLOAT;
  EXPECT_NO_THROW(gather_texel_kernel(context(), {{GATHER_BENCH_BINDING_RECORDS, rgba}}));
  EXPECT_THROW(gather_texel_kernel(context(), {{GATHER_BENCH_BINDING_COUNT, rgba}}), std::invalid_argument)
      << "index out of range";
  EXPECT_THROW(gather_texel_kernel(context(), {{0, rgba}, {0, rgba}}), std::invalid_argument) << "repeated";
  try {
    gather_texel_kernel(context(), {{0, VK_FORMAT_R8G8B8A8_UNORM}});
    FAIL() << "a format the engine does not size";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("R32G32B32A32_SFLOAT"), std::string::npos) << e.what();
  }
}

TEST_F(EngineTest, TexelBindingsAreReadOnlyAndViewWholeElements) {
  kernels::GatherBench bench(context(), kernels::GatherRead::kTexelVec4);
  engine::DeviceArray<float> one_float(context(), "one float", 1), sums(context(), "sums", 4 * 64);
  engine::Sequence seq(context());
  try {  // the benchmark's own size check: one float is not a four-float record
    bench.record(seq, one_float, sums, {1, 1});
    FAIL() << "the record check should refuse one float as a record";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("1 records"), std::string::npos) << e.what();
  }
  try {  // the engine's: 4 bytes hold no four-float texel, and the refusal names the buffer
    (void)one_float.buffer().texel_view(VK_FORMAT_R32G32B32A32_SFLOAT);
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("one float"), std::string::npos) << e.what();
  }
  EXPECT_NE(one_float.buffer().texel_view(VK_FORMAT_R32_SFLOAT), VkBufferView{VK_NULL_HANDLE});
  EXPECT_EQ(one_float.buffer().texel_view(VK_FORMAT_R32_SFLOAT),
            one_float.buffer().texel_view(VK_FORMAT_R32_SFLOAT))
      << "a view is made once per format";

  const auto kernel =
      gather_texel_kernel(context(), {{GATHER_BENCH_BINDING_RECORDS, VK_FORMAT_R32G32B32A32_SFLOAT}});
  engine::DeviceArray<float> records(context(), "records", 4);
  EXPECT_THROW(seq.dispatch(*kernel, {1},
                            {{GATHER_BENCH_BINDING_RECORDS, &records.buffer(), Access::kReadWrite},
                             {GATHER_BENCH_BINDING_SUMS, &sums.buffer(), Access::kWrite}},
                            kernels::GatherBenchParams{1, 1}),
               std::invalid_argument)
      << "a texel binding is read-only";
}

TEST(EngineNoDevice, SelectorThatMatchesNothingIsNamed) {
  engine::ContextOptions options;
  options.device_selector = "no-such-gpu-xyz";
  try {
    engine::Context context(options);
    FAIL() << "expected NoDeviceError";
  } catch (const engine::NoDeviceError& e) {
    EXPECT_NE(std::string(e.what()).find("no-such-gpu-xyz"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace litgs
