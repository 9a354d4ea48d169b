// The models the service holds on the device, by name. A load builds the new model completely (parsed and
// uploaded) before one swap under the lock replaces the old entry, so no request ever sees a half-loaded
// model; a render in flight keeps the model it started with alive (shared_ptr) until it finishes.
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "kernels/splat/rasterizer.h"
#include "tools/serve/image_units.h"

namespace litgs::serve {

// What GET /model says about a model (any thread may read it).
struct ModelSummary {
  std::string name;
  uint64_t version = 0;  // 1 for the first load of this name, +1 per reload
  std::string path;
  size_t gaussians = 0;
  uint32_t channels = 1, sh_degree = 0;
  std::array<double, 3> bounds_min{}, bounds_max{};  // of the means, in the pose frame
  std::string frame;                                 // the frame poses are given in: scene | model
  std::array<double, 3> frame_offset{};              // pose-frame coordinates + this = original world
  uint64_t device_bytes = 0;
  std::optional<ImageUnits> image_units;  // the image channel's data units (levels.json), if known
};

struct DeviceModel {
  ModelSummary summary;
  std::unique_ptr<kernels::DeviceGaussians> gaussians;
};

class ModelStore {
 public:
  // The entry under `name`, or null. Device models are used and released on the device thread only.
  std::shared_ptr<DeviceModel> get(const std::string& name) const;
  // Puts `model` under its summary's name, replacing any older entry (its version is set here).
  void put(std::shared_ptr<DeviceModel> model);
  std::optional<ModelSummary> summary(const std::string& name) const;
  std::vector<ModelSummary> summaries() const;
  uint64_t next_version(const std::string& name) const;
  void clear();  // on the device thread, before its context goes

 private:
  mutable std::mutex mutex_;
  std::map<std::string, std::shared_ptr<DeviceModel>> models_;
};

// `requested` (relative to `models_dir`, or absolute) resolved with every symlink followed; RequestError
// 403 naming it when the result is not inside models_dir's own resolved path, 404 when it does not exist.
std::filesystem::path confine_to_models_dir(const std::filesystem::path& models_dir,
                                            const std::string& requested);

}  // namespace litgs::serve
