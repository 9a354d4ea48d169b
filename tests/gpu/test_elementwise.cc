// The element-wise grid (kernels/elementwise.h, kernels/elementwise.glsl): its shapes, its limits, and a
// kernel dispatched over more elements than one row of 65535 workgroups holds reaching every element once.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "gpu_test.h"
#include "kernels/elementwise.h"
#include "kernels/limits.h"
#include "kernels/optim/adam.h"
#include "kernels/optim/adam_reference.h"
#include "kernels/optim/optim_shared.h"

namespace litgs::kernels {
namespace {

using engine::DeviceArray;
using testing::GpuTest;

class ElementwiseTest : public GpuTest {};

constexpr uint64_t kGroup = ELEMENTWISE_GROUP_SIZE;
constexpr uint64_t kRow = 65535 * kGroup;  // elements in one full row of workgroups

// Every element has an invocation, and fewer than one workgroup per row is padding.
void expect_covers(const engine::Groups& g, uint64_t count) {
  const uint64_t invocations = uint64_t{g.x} * g.y * g.z * kGroup;
  EXPECT_GE(invocations, count) << count;
  EXPECT_LT(invocations, count + uint64_t{g.y} * kGroup) << count;
  EXPECT_LE(g.x, 65535u) << count;
  EXPECT_EQ(g.z, 1u) << count;
}

TEST_F(ElementwiseTest, GridIsOneRowUpTo65535GroupsThenBalancedRows) {
  const engine::Context& c = context();
  for (uint64_t count : {uint64_t{0}, uint64_t{1}, kGroup - 1, kGroup, kGroup + 1, kRow - 1, kRow})
    EXPECT_EQ(elementwise_groups(c, count, "test").y, 1u) << count;
  EXPECT_EQ(elementwise_groups(c, 0, "test").x, 0u);
  EXPECT_EQ(elementwise_groups(c, 1, "test").x, 1u);
  EXPECT_EQ(elementwise_groups(c, kRow, "test").x, 65535u);
  const engine::Groups two = elementwise_groups(c, kRow + 1, "test");
  EXPECT_EQ(two.x, 32768u);
  EXPECT_EQ(two.y, 2u);
  for (uint64_t count : {uint64_t{0}, uint64_t{1}, kGroup + 1, kRow, kRow + 1, 2 * kRow + 17, 100 * kRow - 1,
                         uint64_t{0xFFFFFFFFu} - 65536 * kGroup})
    expect_covers(elementwise_groups(c, count, "test"), count);
}

TEST_F(ElementwiseTest, RefusesCountsBeyondA32BitElementIndexNamingTheCaller) {
  const uint64_t count = uint64_t{1} << 33;
  try {
    elementwise_groups(context(), count, "my/kernel");
    FAIL() << "no exception";
  } catch (const std::length_error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("my/kernel"), std::string::npos) << what;
    EXPECT_NE(what.find(std::to_string(count)), std::string::npos) << what;
  }
}

// One Adam step over more elements than a row of workgroups holds (a grid of two rows): every element is
// updated exactly once. An element skipped keeps m = 0, one updated twice has m = 0.19 g instead of 0.1 g,
// and one updated from another element's index has another element's gradient.
TEST_F(ElementwiseTest, AdamStepOverTwoRowsUpdatesEveryElementOnce) {
  const size_t n = kRow + 1000003;  // 17.8M floats: 71 MB per buffer, within lavapipe's 128 MiB binding
  ASSERT_GT(elementwise_groups(context(), n, "test").y, 1u);
  std::vector<float> grads(n);
  for (size_t j = 0; j < n; ++j) grads[j] = 1.0f + static_cast<float>(j % 1021);
  DeviceArray<float> d_params(context(), "params", n), d_grads(context(), "grads", n), d_m(context(), "m", n),
      d_v(context(), "v", n);
  DeviceArray<uint32_t> counters(context(), "counters", ADAM_COUNTER_SLOTS);
  {
    const std::vector<float> zeros(n, 0.0f);
    d_params.upload(zeros);
    d_m.upload(zeros);
    d_v.upload(zeros);
  }
  d_grads.upload(grads);
  counters.upload(std::vector<uint32_t>(ADAM_COUNTER_SLOTS, 0u));
  const AdamOptions options;
  const float lr = 1e-2f;
  AdamKernel adam(context());
  engine::Sequence s(context());
  adam.record(s, {&d_params.buffer(), &d_grads.buffer(), &d_m.buffer(), &d_v.buffer(), &counters.buffer()}, n,
              options, 1, lr, 0);
  s.submit_and_wait();
  const std::vector<float> m = d_m.download();
  const std::vector<float> p = d_params.download();
  size_t wrong = 0, first_wrong = n;
  for (size_t j = 0; j < n; ++j) {
    double p_ref = 0, m_ref = 0, v_ref = 0;
    adam_reference_step(p_ref, m_ref, v_ref, grads[j], lr, options, 1);
    // float32 rounding: a few ulp (m) and a few ulp of lr (the parameter); a second update doubles both.
    const bool ok = std::abs(m[j] - m_ref) <= 1e-6 * m_ref && std::abs(p[j] - p_ref) <= 1e-5 * lr;
    if (!ok && wrong++ == 0) first_wrong = j;
  }
  if (wrong > 0)
    ADD_FAILURE() << wrong << " of " << n << " elements wrong, the first at " << first_wrong << ": m "
                  << m[first_wrong] << ", param " << p[first_wrong] << ", gradient " << grads[first_wrong];
  EXPECT_EQ(counters.download()[0], 0u);
}

}  // namespace
}  // namespace litgs::kernels
