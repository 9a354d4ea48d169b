// Every client mistake gets a 4xx with a JSON error that names the problem, and the server keeps serving.
#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <chrono>
#include <thread>

#include "serve_fixture.h"

namespace litgs::testing {
namespace {

class ServeBadRequest : public ServeTest {
 protected:
  void TearDown() override {
    // Whatever the mistake, the server still answers.
    const auto res = client()->Get("/healthz");
    ASSERT_TRUE(res) << "the server stopped answering";
    EXPECT_EQ(res->status, 200);
  }
  httplib::Result post(const std::string& path, const std::string& body) {
    return client()->Post(path.c_str(), body, "application/json");
  }
};

TEST_F(ServeBadRequest, MalformedJson) {
  expect_error(post("/render", "{\"pose\": "), 400, "malformed JSON");
  expect_error(post("/models/load", "not json"), 400, "malformed JSON");
}

TEST_F(ServeBadRequest, MissingField) {
  expect_error(post("/render", R"({"width": 8, "height": 8, "intrinsics": {"fov_y_deg": 50}})"), 400,
               "missing field 'pose'");
  expect_error(post("/models/load", R"({"name": "x"})"), 400, "'path'");
}

TEST_F(ServeBadRequest, ExtraField) {
  expect_error(post("/render", render_json("", R"("exposure": 2)")), 400, "unknown field 'exposure'");
  expect_error(client()->Get((std::string("/render?") + kQueryCamera + "&zoom=2").c_str()), 400,
               "unknown query parameter 'zoom'");
  expect_error(post("/models/load", R"({"name": "x", "path": "other.ply", "force": true})"), 400,
               "unknown field 'force'");
}

TEST_F(ServeBadRequest, NanAndInfinity) {
  expect_error(client()->Get("/render?pose=T_cam_world&q=1,0,0,0&t=0,nan,0&fx=60&fy=60&cx=32&cy=24&width=64&"
                             "height=48"),
               400, "'t' is not a number");
  std::string inf = render_json();
  inf.replace(inf.find("\"fx\": 60"), 8, "\"fx\": 1e999");
  expect_error(post("/render", inf), 400, "number overflow parsing '1e999'");
  expect_error(post("/render", R"({"width": NaN})"), 400, "malformed JSON");
}

TEST_F(ServeBadRequest, NonUnitQuaternion) {
  std::string body = render_json();
  body.replace(body.find("[1, 0, 0, 0]"), 12, "[1, 1, 0, 0]");
  expect_error(post("/render", body), 400, "unit quaternion");
}

TEST_F(ServeBadRequest, ZeroAndHugeSizes) {
  std::string zero = render_json();
  zero.replace(zero.find("\"width\": 64"), 11, "\"width\": 0");
  expect_error(post("/render", zero), 400, "'width' is 0");
  std::string huge = render_json();
  huge.replace(huge.find("\"width\": 64, \"height\": 48"), 25, "\"width\": 1000, \"height\": 1000");
  expect_error(post("/render", huge), 400, "above this server's --max-pixels 400000");
  std::string overflow = render_json();
  overflow.replace(overflow.find("\"width\": 64"), 11, "\"width\": 99999999999999999999");
  expect_error(post("/render", overflow), 400, "width");
}

TEST_F(ServeBadRequest, UnknownModel) {
  expect_error(post("/render", render_json("", R"("model": "nope")")), 404, "unknown model 'nope'");
  expect_error(client()->Get("/model?name=nope"), 404, "unknown model 'nope'");
  expect_error(post("/render", render_json("", R"("sh_degree": 3, "model": "default", "bundle": 3)")), 400,
               "'bundle' must be true or false");
}

TEST_F(ServeBadRequest, PathTraversalAndSymlinksOutOfModelsDir) {
  expect_error(post("/models/load", R"({"name": "x", "path": "../outside.ply"})"), 403,
               "outside --models-dir");
  expect_error(post("/models/load", R"({"name": "x", "path": "link.ply"})"), 403, "outside --models-dir");
  expect_error(post("/models/load", R"({"name": "x", "path": "/etc/passwd"})"), 403, "outside --models-dir");
  expect_error(post("/models/load", R"({"name": "x", "path": "missing.ply"})"), 404, "missing.ply");
  expect_error(post("/models/load", R"({"name": "../x", "path": "other.ply"})"), 400, "field 'name'");
  expect_error(post("/models/load", R"({"name": "x", "path": "broken.ply"})"), 400, "broken.ply");
  expect_error(post("/render", render_json("", R"("model": "x")")), 404, "unknown model 'x'");
}

TEST_F(ServeBadRequest, OversizedBody) {
  const std::string big = render_json("", "\"pad\": \"" + std::string(70000, 'x') + "\"");
  expect_error(post("/render", big), 413, "--max-body 65536");
}

TEST_F(ServeBadRequest, WrongMethodAndContentType) {
  const auto put = client()->Put("/render", render_json(), "application/json");
  expect_error(put, 405, "PUT is not allowed on /render");
  EXPECT_EQ(put->get_header_value("Allow"), "GET, POST");
  expect_error(client()->Get("/models/load"), 405, "GET is not allowed on /models/load");
  expect_error(client()->Delete("/model"), 405, "allowed: GET");
  expect_error(client()->Post("/render", render_json(), "text/plain"), 415,
               "Content-Type must be application/json");
  expect_error(client()->Get("/nowhere"), 404, "no such endpoint: GET /nowhere");
}

int connect_to(int port) {
  const int fd = socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_port = htons(static_cast<uint16_t>(port));
  inet_pton(AF_INET, "127.0.0.1", &addr.sin_addr);
  EXPECT_EQ(connect(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr), 0);
  return fd;
}

// What the server sends until it closes the connection; `closed` false if it had not closed it after
// `seconds`.
struct Received {
  std::string text;
  bool closed = false;
};
Received read_until_closed(int fd, int seconds) {
  timeval tv{seconds, 0};
  setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
  Received r;
  char buf[4096];
  for (;;) {
    const ssize_t n = recv(fd, buf, sizeof buf, 0);
    if (n == 0) r.closed = true;
    if (n <= 0) break;
    r.text.append(buf, static_cast<size_t>(n));
  }
  return r;
}

TEST_F(ServeBadRequest, BodylessPutAndPatchAre405NotMalformed) {
  // httplib refuses these before any handler runs; the answer must still name the method as the mistake.
  for (const char* method : {"PUT", "PATCH"}) {
    const int fd = connect_to(port());
    const std::string request =
        std::string(method) + " /render HTTP/1.1\r\nHost: x\r\nConnection: close\r\n\r\n";
    ASSERT_EQ(send(fd, request.data(), request.size(), 0), static_cast<ssize_t>(request.size()));
    const Received r = read_until_closed(fd, 10);
    close(fd);
    EXPECT_EQ(r.text.rfind("HTTP/1.1 405", 0), 0u) << method << ":\n" << r.text;
    EXPECT_NE(r.text.find("Allow: GET, POST"), std::string::npos) << r.text;
    EXPECT_NE(r.text.find(std::string(method) + " is not allowed on /render"), std::string::npos) << r.text;
  }
}

TEST_F(ServeBadRequest, SlowClientIsDisconnectedWithoutBlockingOthers) {
  const int fd = connect_to(port());
  const std::string start = "POST /render HTTP/1.1\r\nHost: x\r\nContent-Type: application/json\r\n";
  ASSERT_EQ(send(fd, start.data(), start.size(), 0), static_cast<ssize_t>(start.size()));
  // While it dawdles, others are served.
  const auto t0 = std::chrono::steady_clock::now();
  const auto res = client()->Post("/render", render_json(), "application/json");
  ASSERT_TRUE(res);
  EXPECT_EQ(res->status, 200);
  // It is dropped after --read-timeout (1 s) of silence, not kept forever.
  const Received got = read_until_closed(fd, 10);
  const double waited = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  EXPECT_TRUE(got.closed) << "the connection was not closed";
  EXPECT_LT(waited, 9.0);
  EXPECT_EQ(got.text.find("200 OK"), std::string::npos) << got.text;
  close(fd);
}

TEST_F(ServeBadRequest, HalfClosedClientGetsAnErrorOrAClose) {
  const int fd = connect_to(port());
  const std::string partial =
      "POST /render HTTP/1.1\r\nHost: x\r\nContent-Type: application/json\r\nContent-Length: "
      "500\r\n\r\n{\"pose\"";
  ASSERT_EQ(send(fd, partial.data(), partial.size(), 0), static_cast<ssize_t>(partial.size()));
  shutdown(fd, SHUT_WR);  // the body will never come
  const Received got = read_until_closed(fd, 10);
  // Either a 400 answer or a plain close; never a render and never a hang.
  EXPECT_TRUE(got.closed) << "the connection was not closed";
  EXPECT_TRUE(got.text.empty() || got.text.find("HTTP/1.1 400") == 0) << got.text;
  close(fd);
}

}  // namespace
}  // namespace litgs::testing
