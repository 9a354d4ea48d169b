#include "host/train/checkpoint.h"

#include <cstring>
#include <fstream>
#include <iterator>

#include "io/atomic_file.h"
#include "io/error.h"
#include "kernels/level/level_shared.h"

namespace litgs::host {
namespace {

constexpr char kMagicV1[8] = {'L', 'I', 'T', 'G', 'S', 'C', 'K', '1'};  // without the run record
constexpr char kMagicV2[8] = {'L', 'I', 'T', 'G', 'S', 'C', 'K', '2'};  // without the level state
constexpr char kMagic[8] = {'L', 'I', 'T', 'G', 'S', 'C', 'K', '3'};

template <class T>
void put(std::ostream& out, const T& v) {
  out.write(reinterpret_cast<const char*>(&v), sizeof(T));
}
template <class T>
void put_vector(std::ostream& out, const std::vector<T>& v) {
  put<uint64_t>(out, v.size());
  out.write(reinterpret_cast<const char*>(v.data()), static_cast<std::streamsize>(v.size() * sizeof(T)));
}

// Reads from an in-memory file with bounds checks that name the byte offset.
struct Reader {
  const std::filesystem::path& path;
  const std::vector<char>& bytes;
  size_t at = 0;
  template <class T>
  T get() {
    if (bytes.size() - at < sizeof(T)) io::fail_at_byte(path, at, "checkpoint truncated");
    T v;
    std::memcpy(&v, bytes.data() + at, sizeof(T));
    at += sizeof(T);
    return v;
  }
  template <class T>
  std::vector<T> get_vector(uint64_t expected = UINT64_MAX) {
    const uint64_t n = get<uint64_t>();
    if (expected != UINT64_MAX && n != expected)
      io::fail_at_byte(path, at,
                       "array of " + std::to_string(n) + " values, expected " + std::to_string(expected));
    if (n > (bytes.size() - at) / sizeof(T))
      io::fail_at_byte(path, at, "checkpoint truncated (array of " + std::to_string(n) + ")");
    std::vector<T> v(n);
    if (n > 0) std::memcpy(v.data(), bytes.data() + at, n * sizeof(T));  // data() may be null when empty
    at += n * sizeof(T);
    return v;
  }
};

}  // namespace

void write_checkpoint(const std::filesystem::path& path, const Checkpoint& c) {
  c.state.check();
  io::write_file_atomic(path, [&](std::ostream& out) {
    out.write(kMagic, sizeof kMagic);
    put<uint32_t>(out, c.iteration);
    put_vector(out, c.view_order);
    put<uint32_t>(out, c.order_position);
    put_vector(out, std::vector<char>(c.rng_state.begin(), c.rng_state.end()));
    const auto& m = c.state.model;
    put<uint32_t>(out, m.channels);
    put<uint32_t>(out, m.sh_degree);
    put_vector(out, m.means);
    put_vector(out, m.log_scales);
    put_vector(out, m.quats);
    put_vector(out, m.opacity_logits);
    put_vector(out, m.sh);
    for (const auto& v : c.state.exp_avg) put_vector(out, v);
    for (const auto& v : c.state.exp_avg_sq) put_vector(out, v);
    put_vector(out, c.state.grad_accum);
    put_vector(out, c.state.denom);
    put_vector(out, c.state.max_radius);
    const std::string record = to_json(c.record).dump();
    put_vector(out, std::vector<char>(record.begin(), record.end()));
    put_vector(out, c.level_state);
  });
}

std::filesystem::path checkpoint_path(const std::filesystem::path& out_dir, uint32_t iteration) {
  return out_dir / "checkpoints" / ("iter_" + std::to_string(iteration) + ".ckpt");
}

std::filesystem::path newest_checkpoint(const std::filesystem::path& dir) {
  namespace fs = std::filesystem;
  fs::path best;
  uint32_t best_it = 0;
  if (!fs::is_directory(dir / "checkpoints")) return best;
  for (const auto& e : fs::directory_iterator(dir / "checkpoints")) {
    // iter_<digits>.ckpt only: temporaries of an interrupted write (iter_N.ckpt.tmp-...) and other files are
    // not checkpoints.
    const std::string name = e.path().filename().string();
    if (name.rfind("iter_", 0) != 0 || e.path().extension() != ".ckpt") continue;
    const std::string digits = name.substr(5, name.size() - 5 - 5);
    if (digits.empty() || digits.size() > 9 || digits.find_first_not_of("0123456789") != std::string::npos)
      continue;
    const uint32_t it = static_cast<uint32_t>(std::stoul(digits));
    if (best.empty() || it > best_it) best = e.path(), best_it = it;
  }
  return best;
}

Checkpoint read_checkpoint(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) io::fail(path, 0, "cannot open the checkpoint");
  const std::vector<char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  auto magic_is = [&](const char* magic) {
    return bytes.size() >= sizeof kMagic && std::memcmp(bytes.data(), magic, sizeof kMagic) == 0;
  };
  const bool v1 = magic_is(kMagicV1), v2 = magic_is(kMagicV2);
  if (!v1 && !v2 && !magic_is(kMagic)) io::fail_at_byte(path, 0, "not a LIT-GS checkpoint (bad magic)");
  Reader r{path, bytes, sizeof kMagic};
  Checkpoint c;
  c.iteration = r.get<uint32_t>();
  c.view_order = r.get_vector<uint32_t>();
  c.order_position = r.get<uint32_t>();
  const auto rng = r.get_vector<char>();
  c.rng_state.assign(rng.begin(), rng.end());
  auto& m = c.state.model;
  m.channels = r.get<uint32_t>();
  m.sh_degree = r.get<uint32_t>();
  if (m.channels < 1 || m.channels > 4 || m.sh_degree > 3)
    io::fail_at_byte(path, r.at, "bad channels or SH degree");
  m.means = r.get_vector<float>();
  const uint64_t n = m.means.size() / 3;
  m.log_scales = r.get_vector<float>(3 * n);
  m.quats = r.get_vector<float>(4 * n);
  m.opacity_logits = r.get_vector<float>(n);
  m.sh = r.get_vector<float>(n * m.sh_coeffs() * m.channels);
  for (auto& v : c.state.exp_avg) v = r.get_vector<float>();
  for (auto& v : c.state.exp_avg_sq) v = r.get_vector<float>();
  c.state.grad_accum = r.get_vector<float>(n);
  c.state.denom = r.get_vector<uint32_t>(n);
  c.state.max_radius = r.get_vector<float>(n);
  c.has_record = !v1;
  if (!v1) {
    const size_t record_at = r.at;
    const auto text = r.get_vector<char>();
    try {
      c.record = run_record_from_json(nlohmann::json::parse(text.begin(), text.end()));
    } catch (const nlohmann::json::exception& e) {
      io::fail_at_byte(path, record_at, std::string("bad run record: ") + e.what());
    }
  }
  if (!v1 && !v2) {
    c.level_state = r.get_vector<float>();
    if (c.level_state.size() % LEVEL_STRIDE != 0 || c.level_state.size() == LEVEL_STRIDE)
      io::fail_at_byte(path, r.at,
                       "level state of " + std::to_string(c.level_state.size()) +
                           " values is not whole rows of frames and the shared row");
  }
  if (r.at != bytes.size()) io::fail_at_byte(path, r.at, "trailing bytes after the checkpoint");
  try {
    c.state.check();
  } catch (const std::exception& e) {
    io::fail(path, 0, std::string("inconsistent checkpoint: ") + e.what());
  }
  if (c.order_position > c.view_order.size()) io::fail(path, 0, "view order position out of range");
  return c;
}

}  // namespace litgs::host
