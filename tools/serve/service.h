// The render service without its HTTP layer: the models on the device, the device thread and its queue,
// the scene's cameras. http_server.cc maps requests onto it.
#pragma once

#include <atomic>
#include <cstdint>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "engine/context.h"
#include "io/scene.h"
#include "kernels/splat/rasterizer.h"
#include "tools/serve/device_worker.h"
#include "tools/serve/metrics.h"
#include "tools/serve/model_store.h"
#include "tools/serve/render_output.h"
#include "tools/serve/render_request.h"

namespace litgs::serve {

struct ServeOptions {
  std::string model;   // loaded as "default" at start
  std::string scene;   // optional: poses in its frame, its cameras in GET /model
  std::string levels;  // train's levels.json of --model (default: the one beside it, if any): data units
  std::string host = "127.0.0.1";
  int port = 8080;        // 0: any free port (printed)
  size_t max_queue = 32;  // renders waiting for the device before 503
  uint64_t max_pixels = 4'194'304;
  std::string models_dir;         // POST /models/load reads only inside it (empty: loading refused)
  double request_timeout_s = 30;  // a render not finished by then is answered 503
  size_t max_body_bytes = 1 << 20;
  int read_timeout_s = 5;  // a client that sends nothing for this long is disconnected
  size_t threads = 0;      // HTTP worker threads; 0: max_queue + 4
  void check() const;      // std::invalid_argument naming the bad option
};

// A scene camera for clients to jump to (GET /model).
struct SceneCamera {
  size_t index = 0;
  double t_s = 0;
  std::string image;  // file name of the real frame
  kernels::SplatCamera camera;
};

class Service {
 public:
  explicit Service(const ServeOptions& options);  // creates the device thread and loads --model
  ~Service();

  const ServeOptions& options() const { return options_; }
  ModelStore& models() { return models_; }
  Metrics& metrics() { return metrics_; }
  const std::vector<SceneCamera>& scene_cameras() const { return scene_cameras_; }
  size_t queue_depth() const { return worker_->depth(); }
  // Render requests accepted and not yet answered (queued, on the device, or being encoded).
  size_t renders_in_flight() const { return renders_in_flight_.load(); }
  const engine::DeviceInfo& device() const { return device_info_; }
  // Validation-layer errors so far, where the layer is on (LITGS_VALIDATION=1; the tests use it).
  std::optional<size_t> validation_errors() const;

  // Renders on the device thread. RequestError for the client's mistakes (unknown model 404, a request the
  // model cannot serve 400), 503 when the queue is full or the request timed out.
  RenderedView render(const RenderRequest& request, ModelSummary* used);
  // Loads (or reloads) `name` from `path` (already confined): parsed here, uploaded on the device thread,
  // then swapped in atomically.
  // The image units come from `levels` if given, else from a levels.json beside `path`.
  ModelSummary load(const std::string& name, const std::filesystem::path& path,
                    const std::string& levels = {});
  // The real frame `index` of the scene as an 8-bit PNG (16-bit frames stretched min-max); 404 if none.
  std::vector<uint8_t> scene_frame_png(size_t index) const;
  // Finishes the queued device work and stops the device thread.
  void stop();

 private:
  std::atomic<size_t> renders_in_flight_{0};
  template <class Result, class Job>
  Result on_device(Job&& job, double timeout_s, const char* what);

  ServeOptions options_;
  std::optional<io::Scene> scene_;
  std::optional<Eigen::Vector3d> scene_offset_;
  std::vector<SceneCamera> scene_cameras_;
  ModelStore models_;
  Metrics metrics_;
  engine::DeviceInfo device_info_;
  bool validation_enabled_ = false;
  // Owned by the device thread (created and destroyed there).
  std::unique_ptr<engine::Context> context_;
  std::map<uint32_t, std::unique_ptr<kernels::Rasterizer>> rasterizers_;  // by channel count
  std::unique_ptr<DeviceWorker> worker_;
};

}  // namespace litgs::serve
