#include "tools/serve/service.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <future>
#include <iostream>

#include "host/train/training_data.h"
#include "tools/render_view.h"

namespace litgs::serve {

namespace fs = std::filesystem;

void ServeOptions::check() const {
  if (model.empty()) throw std::invalid_argument("--model is required");
  if (port < 0 || port > 65535) throw std::invalid_argument("--port must be in [0, 65535]");
  if (max_queue < 1) throw std::invalid_argument("--max-queue must be at least 1");
  if (max_pixels < 1) throw std::invalid_argument("--max-pixels must be at least 1");
  if (!(request_timeout_s > 0)) throw std::invalid_argument("--request-timeout must be positive");
  if (read_timeout_s < 1) throw std::invalid_argument("--read-timeout must be at least 1 s");
  if (max_body_bytes < 1024) throw std::invalid_argument("--max-body must be at least 1024 bytes");
  if (!models_dir.empty() && !fs::is_directory(models_dir))
    throw std::invalid_argument("--models-dir " + models_dir + " is not a directory");
}

Service::Service(const ServeOptions& options) : options_(options) {
  options_.check();
  if (!options_.scene.empty()) {
    io::SceneReadOptions read;
    read.check_images = false;
    read.load_map = false;
    scene_ = io::read_scene(options_.scene, read);
    scene_offset_ = scene_->config.world_offset_m;
    for (size_t i = 0; i < scene_->frames.size(); ++i) {
      try {
        SceneCamera c;
        c.index = i;
        c.t_s = scene_->frames[i].t_s;
        c.image = scene_->frames[i].image.filename().string();
        c.camera = host::training_camera(options_.scene, *scene_, c.t_s, host::TrainingDataOptions{});
        scene_cameras_.push_back(c);
      } catch (const std::invalid_argument&) {
        // a frame outside the trajectory has no pose: not offered
      }
    }
  }
  worker_ = std::make_unique<DeviceWorker>(
      options_.max_queue,
      [this] {
        context_ = std::make_unique<engine::Context>();
        device_info_ = context_->info();
        validation_enabled_ = context_->validation_enabled();
      },
      [this] {
        rasterizers_.clear();
        models_.clear();  // device models are released on the device thread, before the context
        context_.reset();
      });
  worker_->wait_ready();
  load("default", options_.model, options_.levels);
}

Service::~Service() {
  stop();
}

std::optional<size_t> Service::validation_errors() const {
  if (!validation_enabled_) return std::nullopt;
  return context_ ? context_->validation_error_count() : 0;
}

void Service::stop() {
  if (worker_) worker_->stop();
}

template <class Result, class Job>
Result Service::on_device(Job&& job, double timeout_s, const char* what) {
  struct Pending {
    std::promise<Result> promise;
    std::atomic<bool> abandoned{false};
  };
  auto pending = std::make_shared<Pending>();
  std::future<Result> future = pending->promise.get_future();
  const bool queued = worker_->try_post([pending, job = std::forward<Job>(job)]() mutable {
    if (pending->abandoned) return;  // its client was answered 503 already
    try {
      pending->promise.set_value(job());
    } catch (...) {
      pending->promise.set_exception(std::current_exception());
    }
  });
  if (!queued)
    throw RequestError(503, std::string("the device queue is full (") + std::to_string(worker_->depth()) +
                                " waiting, --max-queue " + std::to_string(options_.max_queue) +
                                "): retry later");
  if (future.wait_for(std::chrono::duration<double>(timeout_s)) != std::future_status::ready) {
    pending->abandoned = true;
    throw RequestError(503, std::string(what) + " timed out after " + std::to_string(timeout_s) +
                                " s waiting for the device (--request-timeout): retry later");
  }
  return future.get();
}

RenderedView Service::render(const RenderRequest& r, ModelSummary* used) {
  ++renders_in_flight_;
  struct InFlight {
    std::atomic<size_t>& count;
    ~InFlight() { --count; }
  } counted{renders_in_flight_};
  const std::optional<ModelSummary> summary = models_.summary(r.model);
  if (!summary) {
    std::string names;
    for (const ModelSummary& m : models_.summaries()) names += (names.empty() ? "" : ", ") + m.name;
    throw RequestError(404, "unknown model '" + r.model + "' (loaded: " + names + ")");
  }
  if (r.sh_degree > static_cast<int>(summary->sh_degree))
    throw RequestError(400, "field 'sh_degree' is " + std::to_string(r.sh_degree) + " but model '" + r.model +
                                "' has degree " + std::to_string(summary->sh_degree));
  if (r.image.palette && summary->channels != 1)
    throw RequestError(400, "field 'outputs.image.palette' needs a one-channel model; '" + r.model +
                                "' has " + std::to_string(summary->channels) + " channels");
  kernels::SplatCamera camera = r.camera;
  camera.sh_degree = r.sh_degree < 0 ? summary->sh_degree : static_cast<uint32_t>(r.sh_degree);
  try {
    camera.check();
  } catch (const std::invalid_argument& e) {
    throw RequestError(400, std::string("bad camera: ") + e.what());
  }
  const auto started = std::chrono::steady_clock::now();
  const double timeout = options_.request_timeout_s;
  struct Done {
    RenderedView view;
    ModelSummary summary;
  };
  Done done = on_device<Done>(
      [this, camera, name = r.model, started, timeout] {
        if (std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count() > timeout)
          throw RequestError(503, "render timed out waiting for the device (--request-timeout): retry later");
        const std::shared_ptr<DeviceModel> model = models_.get(name);
        std::unique_ptr<kernels::Rasterizer>& rasterizer = rasterizers_[model->summary.channels];
        if (!rasterizer)
          rasterizer = std::make_unique<kernels::Rasterizer>(*context_, model->summary.channels);
        const auto t0 = std::chrono::steady_clock::now();
        rasterizer->forward(*model->gaussians, camera);
        kernels::RenderImages<float> images = rasterizer->download_images();
        Done d;
        d.view.device_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        d.view.width = camera.width;
        d.view.height = camera.height;
        d.view.channels = model->summary.channels;
        d.view.image = std::move(images.image);
        d.view.depth = std::move(images.depth);
        d.view.alpha = std::move(images.alpha);
        d.view.intersections = images.intersections;
        d.summary = model->summary;
        return d;
      },
      options_.request_timeout_s, "render");
  metrics_.count_render(done.view.device_seconds);
  if (used) *used = done.summary;
  return std::move(done.view);
}

ModelSummary Service::load(const std::string& name, const fs::path& path, const std::string& levels) {
  // Parsing is CPU work: done here, on the HTTP thread, while the device keeps rendering.
  auto framed = std::make_shared<tools::FramedModel>(
      tools::load_framed_model(path, "auto", scene_offset_, options_.scene));
  ModelSummary s;
  s.name = name;
  s.path = path.string();
  s.gaussians = framed->model.size();
  s.channels = framed->model.channels;
  s.sh_degree = framed->model.sh_degree;
  s.frame = framed->frame;
  s.image_units = find_image_units(path, levels);
  for (int a = 0; a < 3; ++a) {
    s.frame_offset[a] = framed->frame_offset[a];
    s.bounds_min[a] = s.gaussians ? 1e300 : 0;
    s.bounds_max[a] = s.gaussians ? -1e300 : 0;
  }
  for (size_t i = 0; i < s.gaussians; ++i)
    for (int a = 0; a < 3; ++a) {
      const double x = framed->model.means[3 * i + a];
      if (!std::isfinite(x)) continue;
      s.bounds_min[a] = std::min(s.bounds_min[a], x);
      s.bounds_max[a] = std::max(s.bounds_max[a], x);
    }
  return on_device<ModelSummary>(
      [this, framed, s]() mutable {
        auto model = std::make_shared<DeviceModel>();
        const uint64_t before = engine::Buffer::live_bytes();
        model->gaussians = std::make_unique<kernels::DeviceGaussians>(*context_, framed->model);
        s.device_bytes = engine::Buffer::live_bytes() - before;
        s.version = models_.next_version(s.name);  // loads run on this one thread: no race on the version
        model->summary = s;
        models_.put(model);
        return s;
      },
      600.0, "model load");
}

std::vector<uint8_t> Service::scene_frame_png(size_t index) const {
  const auto it = std::find_if(scene_cameras_.begin(), scene_cameras_.end(),
                               [&](const SceneCamera& c) { return c.index == index; });
  if (!scene_ || it == scene_cameras_.end())
    throw RequestError(404, "no scene frame " + std::to_string(index) + " (see GET /model's cameras)");
  io::Image frame = io::load_frame(options_.scene, *scene_, index);
  if (frame.bit_depth == 16) {  // raw counts: stretched to 8 bits for display
    const auto [lo, hi] = std::minmax_element(frame.data.begin(), frame.data.end());
    const double low = *lo, range = std::max(1.0, double(*hi) - low);
    for (uint16_t& v : frame.data) v = static_cast<uint16_t>(std::lround((v - low) * 255.0 / range));
    frame.bit_depth = 8;
  }
  return io::encode_png(frame);
}

}  // namespace litgs::serve
