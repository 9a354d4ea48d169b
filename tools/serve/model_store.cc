#include "tools/serve/model_store.h"

#include "tools/serve/request_error.h"

namespace litgs::serve {

namespace fs = std::filesystem;

std::shared_ptr<DeviceModel> ModelStore::get(const std::string& name) const {
  std::lock_guard lock(mutex_);
  const auto it = models_.find(name);
  return it == models_.end() ? nullptr : it->second;
}

void ModelStore::put(std::shared_ptr<DeviceModel> model) {
  std::shared_ptr<DeviceModel> old;  // released after the lock, outside readers' way
  std::lock_guard lock(mutex_);
  std::shared_ptr<DeviceModel>& slot = models_[model->summary.name];
  old = std::move(slot);
  slot = std::move(model);
}

std::optional<ModelSummary> ModelStore::summary(const std::string& name) const {
  std::lock_guard lock(mutex_);
  const auto it = models_.find(name);
  if (it == models_.end()) return std::nullopt;
  return it->second->summary;
}

std::vector<ModelSummary> ModelStore::summaries() const {
  std::lock_guard lock(mutex_);
  std::vector<ModelSummary> out;
  for (const auto& [name, m] : models_) out.push_back(m->summary);
  return out;
}

uint64_t ModelStore::next_version(const std::string& name) const {
  std::lock_guard lock(mutex_);
  const auto it = models_.find(name);
  return it == models_.end() ? 1 : it->second->summary.version + 1;
}

void ModelStore::clear() {
  std::lock_guard lock(mutex_);
  models_.clear();
}

fs::path confine_to_models_dir(const fs::path& models_dir, const std::string& requested) {
  if (requested.empty()) throw RequestError(400, "field 'path' is empty");
  if (requested.find('\0') != std::string::npos) throw RequestError(400, "field 'path' holds a NUL byte");
  std::error_code ec;
  const fs::path root = fs::canonical(models_dir, ec);
  if (ec) throw RequestError(403, "model loading is off: --models-dir is not set or does not exist");
  const fs::path candidate = fs::path(requested).is_absolute() ? fs::path(requested) : root / requested;
  const fs::path resolved = fs::weakly_canonical(candidate, ec);  // follows every symlink that exists
  if (ec) throw RequestError(400, "path '" + requested + "' cannot be resolved: " + ec.message());
  const auto [root_end, unused] = std::mismatch(root.begin(), root.end(), resolved.begin(), resolved.end());
  if (root_end != root.end() || resolved == root)
    throw RequestError(403, "path '" + requested + "' resolves to " + resolved.string() +
                                ", outside --models-dir " + root.string() + " (symlinks are followed)");
  if (!fs::is_regular_file(resolved, ec))
    throw RequestError(404, "path '" + requested + "' is not a file inside --models-dir");
  return resolved;
}

}  // namespace litgs::serve
