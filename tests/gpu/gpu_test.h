// A GPU test fixture: one shared Vulkan context (lavapipe in CI) with the validation layer on; any
// validation error during a test fails that test.
#pragma once

#include <gtest/gtest.h>

#include <memory>

#include "engine/context.h"

namespace litgs::testing {

class GpuTest : public ::testing::Test {
 public:
  static void SetUpTestSuite() {
    if (!context_) {
      engine::ContextOptions options = engine::ContextOptions::from_environment();
      options.validation = true;
      context_ = std::make_unique<engine::Context>(options);
    }
  }
  static void TearDownTestSuite() { context_.reset(); }

 protected:
  void SetUp() override { context_->clear_validation_messages(); }
  void TearDown() override {
    const auto messages = context_->validation_messages();
    EXPECT_EQ(context_->validation_error_count(), 0u) << "validation errors during the test";
    for (const auto& m : messages) ADD_FAILURE() << "validation message: " << m;
  }
  engine::Context& context() { return *context_; }

 private:
  static inline std::unique_ptr<engine::Context> context_;
};

}  // namespace litgs::testing
