// The service under concurrent load: a model reloaded while clients render loses no request, and a full
// queue answers 503 with Retry-After instead of piling up.
#include <atomic>
#include <set>
#include <thread>

#include "serve_fixture.h"

namespace litgs::testing {
namespace {

TEST_F(ServeTest, ReloadUnderLoadFailsNoRequest) {
  auto loader = client();
  const auto first =
      loader->Post("/models/load", R"({"name": "live", "path": "same.ply"})", "application/json");
  ASSERT_TRUE(first);
  ASSERT_EQ(first->status, 200) << first->body;
  std::atomic<bool> done{false};
  std::atomic<int> ok{0}, failed{0};
  std::mutex mutex;
  std::set<std::string> versions;
  std::string first_failure;
  std::vector<std::thread> clients;
  for (int c = 0; c < 6; ++c)
    clients.emplace_back([&] {
      auto http = client();
      while (!done) {
        const auto res = http->Post("/render", render_json("", R"("model": "live")"), "application/json");
        std::lock_guard lock(mutex);
        if (res && res->status == 200) {
          ++ok;
          versions.insert(res->get_header_value("X-Model-Version"));
        } else {
          ++failed;
          if (first_failure.empty())
            first_failure = res ? std::to_string(res->status) + " " + res->body : "no response";
        }
      }
    });
  for (int i = 0; i < 6; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(60));
    const auto res =
        loader->Post("/models/load", R"({"name": "live", "path": "same.ply"})", "application/json");
    ASSERT_TRUE(res);
    EXPECT_EQ(res->status, 200) << res->body;
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(60));
  done = true;
  for (auto& t : clients) t.join();
  EXPECT_EQ(failed.load(), 0) << first_failure;
  EXPECT_GT(ok.load(), 20);
  EXPECT_GE(versions.size(), 2u) << "renders saw several versions of the model";
  EXPECT_EQ(versions.count("live@7"), 1u) << "the last reload is version 7";
}

class ServeSmallQueue : public ServeTest {
 public:
  static void SetUpTestSuite() {
    extra_args_ = {"--max-queue", "1", "--threads", "24", "--request-timeout", "5"};
    ServeTest::SetUpTestSuite();
  }
};

TEST_F(ServeSmallQueue, FullQueueAnswers503WithRetryAfter) {
  std::atomic<int> ok{0}, busy{0}, other{0}, missing_retry_after{0};
  std::atomic<int> ready{0};
  std::vector<std::thread> clients;
  for (int c = 0; c < 16; ++c)
    clients.emplace_back([&] {
      auto http = client();
      ++ready;
      while (ready < 16) std::this_thread::yield();
      const auto res = http->Post("/render", render_json("", "\"sh_degree\": 3"), "application/json");
      if (res && res->status == 200) {
        ++ok;
      } else if (res && res->status == 503) {
        ++busy;
        if (res->get_header_value("Retry-After").empty()) ++missing_retry_after;
        if (res->body.find("queue is full") == std::string::npos) ++other;
      } else {
        ++other;
      }
    });
  for (auto& t : clients) t.join();
  EXPECT_GE(ok.load(), 1);
  EXPECT_GE(busy.load(), 1) << "16 simultaneous renders against --max-queue 1";
  EXPECT_EQ(other.load(), 0);
  EXPECT_EQ(missing_retry_after.load(), 0);
  const auto metrics = client()->Get("/metrics");
  ASSERT_TRUE(metrics);
  EXPECT_NE(metrics->body.find("litgs_http_requests_total{endpoint=\"/render\",status=\"503\"}"),
            std::string::npos);
}

class ServeTimeout : public ServeTest {
 public:
  static void SetUpTestSuite() {
    extra_args_ = {"--max-queue", "64", "--threads", "24", "--request-timeout", "0.001"};
    ServeTest::SetUpTestSuite();
  }
};

TEST_F(ServeTimeout, RendersPastTheRequestTimeoutAnswer503) {
  std::atomic<int> timed_out{0}, other{0};
  std::vector<std::thread> clients;
  for (int c = 0; c < 8; ++c)
    clients.emplace_back([&] {
      const auto res = client()->Post("/render", render_json(), "application/json");
      if (res && res->status == 503 && res->body.find("timed out") != std::string::npos &&
          res->get_header_value("Retry-After") == "1")
        ++timed_out;
      else if (!res || res->status != 200)
        ++other;
    });
  for (auto& t : clients) t.join();
  EXPECT_GE(timed_out.load(), 1);
  EXPECT_EQ(other.load(), 0);
}

}  // namespace
}  // namespace litgs::testing
