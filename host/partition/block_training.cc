#include "host/partition/block_training.h"

#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <mutex>
#include <sstream>
#include <stdexcept>
#include <thread>

#include "host/partition/partition_scene.h"
#include "host/run/child_process.h"
#include "io/scene_yaml.h"

namespace litgs::host::partition {
namespace fs = std::filesystem;

namespace {

fs::path block_dir(const fs::path& dir, const std::string& name) {
  return dir / kBlocksDir / name;
}
fs::path block_model(const fs::path& dir, const std::string& name) {
  return block_dir(dir, name) / kBlockTrainDir / "point_cloud.ply";
}
fs::path block_trace(const fs::path& dir, const std::string& name) {
  return block_dir(dir, name) / kBlockTrainDir / kBlockTrace;
}
fs::path block_log(const fs::path& dir, const std::string& name) {
  return block_dir(dir, name) / "train.log";
}

std::vector<std::string> train_command(const fs::path& dir, const std::string& name,
                                       const std::vector<std::string>& extra) {
  std::vector<std::string> args = {"train", block_dir(dir, name).string(), "--out",
                                   (block_dir(dir, name) / kBlockTrainDir).string()};
  args.insert(args.end(), extra.begin(), extra.end());
  args.insert(args.end(), {"--trace", block_trace(dir, name).string()});
  return args;
}

std::string shell_quote(const std::string& s) {
  std::string out = "'";
  for (char c : s) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

// `program` itself if it names a path, else the first executable of that name on PATH; empty if none.
fs::path find_program(const std::string& program) {
  if (program.find('/') != std::string::npos) return fs::exists(program) ? fs::path(program) : fs::path();
  const char* path = std::getenv("PATH");
  std::stringstream dirs(path ? path : "");
  for (std::string d; std::getline(dirs, d, ':');) {
    const fs::path candidate = fs::path(d.empty() ? "." : d) / program;
    std::error_code ec;
    if (fs::is_regular_file(candidate, ec) &&
        (fs::status(candidate, ec).permissions() & fs::perms::owner_exec) != fs::perms::none)
      return candidate;
  }
  return {};
}

std::string last_lines(const std::string& text, size_t lines) {
  size_t pos = text.size();
  for (size_t n = 0; n <= lines && pos > 0; ++n) pos = text.rfind('\n', pos - 1);
  return pos == std::string::npos ? text : text.substr(pos + 1);
}

void throw_if_failed(const BlockTrainingReport& r, const std::string& executor) {
  std::string failed;
  for (const auto& b : r.blocks)
    if (b.state == "failed") failed += "\n  " + b.name + ": see " + b.log.string();
  if (!failed.empty())
    throw std::runtime_error("train blocks (" + executor +
                             "): blocks failed; the others are kept, and a rerun " +
                             "trains only what is missing:" + failed);
}

BlockTrainingReport train_local(const fs::path& dir, const fs::path& engine,
                                const std::vector<PartitionBlock>& blocks, const BlockTrainingOptions& o,
                                const BlockProgress& progress) {
  BlockTrainingReport r;
  r.blocks.resize(blocks.size());
  std::atomic<size_t> next{0};
  std::mutex mutex;
  auto worker = [&] {
    for (size_t k; (k = next++) < blocks.size();) {
      BlockOutcome& b = r.blocks[k];
      b.name = blocks[k].name;
      b.log = block_log(dir, b.name);
      if (fs::exists(block_model(dir, b.name))) {
        b.state = "done before";
      } else {
        std::ostream quiet(nullptr);
        fs::remove(block_trace(dir, b.name));  // a failed try's reports: train appends to the file
        const run::ChildResult c =
            run::run_child(engine, train_command(dir, b.name, o.train_args), b.log, quiet);
        b.seconds = c.seconds;
        const bool ok = c.exit_code == 0 && fs::exists(block_model(dir, b.name));
        b.state = ok ? "trained" : "failed";
        if (!ok) b.tail = last_lines(c.tail, 5);
      }
      const std::lock_guard<std::mutex> lock(mutex);
      if (progress) progress(b);
    }
  };
  std::vector<std::thread> threads;
  for (size_t t = 0; t < std::max<size_t>(1, std::min(o.parallel, blocks.size())); ++t)
    threads.emplace_back(worker);
  for (auto& t : threads) t.join();
  return r;
}

BlockTrainingReport train_slurm(const fs::path& dir, const fs::path& engine,
                                const std::vector<PartitionBlock>& blocks, const BlockTrainingOptions& o,
                                const BlockProgress& progress) {
  const fs::path sbatch = find_program(o.sbatch);
  if (sbatch.empty())
    throw std::runtime_error(
        "train blocks: the slurm executor needs sbatch, and '" + o.sbatch +
        "' is not on PATH: install Slurm's client (Debian slurm-client), load its module, "
        "or use the local executor");
  BlockTrainingReport r;
  std::vector<std::string> pending;
  for (const auto& b : blocks)
    if (!fs::exists(block_model(dir, b.name))) {
      pending.push_back(b.name);
      fs::remove(block_trace(dir, b.name));  // a failed try's reports: train appends to the file
    }
  if (!pending.empty()) {
    BlockTrainingOptions with_defaults = o;
    with_defaults.slurm = default_slurm_resources(dir, o.slurm);
    r.script = dir / "train-blocks.sbatch";
    fs::create_directories(dir / "slurm");
    {
      std::ofstream out(r.script);
      out << slurm_array_script(dir, fs::absolute(engine), pending, with_defaults);
      if (!out) throw std::runtime_error("train blocks: cannot write " + r.script.string());
    }
    std::ostream quiet(nullptr);
    const run::ChildResult c = run::run_child(sbatch, {"--parsable", "--wait", r.script.string()},
                                              dir / "slurm" / "sbatch.log", quiet);
    if (c.exit_code != 0 && c.tail.find_first_of("0123456789") != 0)
      throw std::runtime_error("train blocks (slurm): sbatch did not take the job (exit " +
                               std::to_string(c.exit_code) + "): " + last_lines(c.tail, 5));
  }
  for (const auto& b : blocks) {
    BlockOutcome out{b.name, "", block_log(dir, b.name), 0, ""};
    const bool was_pending = std::find(pending.begin(), pending.end(), b.name) != pending.end();
    out.state = !was_pending ? "done before" : fs::exists(block_model(dir, b.name)) ? "trained" : "failed";
    r.blocks.push_back(out);
    if (progress) progress(out);
  }
  return r;
}

}  // namespace

Executor executor_from(const std::string& name) {
  if (name == "local") return Executor::kLocal;
  if (name == "slurm") return Executor::kSlurm;
  throw std::invalid_argument("executor: '" + name + "' is not local or slurm");
}

SlurmResources default_slurm_resources(const fs::path& dir, SlurmResources r) {
  if (!r.mem.empty()) return r;
  double largest = 0;
  for (const auto& b : read_partition(dir, "train blocks").blocks) {
    const io::SceneConfig c = io::read_scene_yaml(block_dir(dir, b.name) / "scene.yaml");
    largest = std::max(largest, static_cast<double>(b.views) * c.camera.width * c.camera.height);
  }
  const double bytes = 4.0 * 4.0 * largest + 4.0 * (1ull << 30);
  r.mem = std::to_string(static_cast<long long>(std::ceil(bytes / (1ull << 30)))) + "G";
  return r;
}

std::string slurm_array_script(const fs::path& dir, const fs::path& engine,
                               const std::vector<std::string>& pending, const BlockTrainingOptions& o) {
  const fs::path abs = fs::absolute(dir);
  std::ostringstream s;
  s << "#!/bin/bash\n"
    << "# Written by litgs-engine: trains the blocks of " << abs.string() << " that have no model yet,\n"
    << "# one array task each, through the same binary. Submit with: sbatch --wait THIS\n"
    << "#SBATCH --job-name=litgs-blocks\n"
    << "#SBATCH --array=0-" << pending.size() - 1 << "\n"
    << "#SBATCH --output=" << (abs / "slurm" / "%A_%a.out").string() << "\n";
  if (!o.slurm.gres.empty()) s << "#SBATCH --gres=" << o.slurm.gres << "\n";
  if (!o.slurm.mem.empty()) s << "#SBATCH --mem=" << o.slurm.mem << "\n";
  if (!o.slurm.time.empty()) s << "#SBATCH --time=" << o.slurm.time << "\n";
  if (!o.slurm.partition.empty()) s << "#SBATCH --partition=" << o.slurm.partition << "\n";
  for (const auto& e : o.slurm.extra) s << "#SBATCH " << e << "\n";
  s << "set -euo pipefail\nblocks=(";
  for (size_t i = 0; i < pending.size(); ++i) s << (i ? " " : "") << shell_quote(pending[i]);
  s << ")\nname=${blocks[$SLURM_ARRAY_TASK_ID]}\n"
    << "scene=" << shell_quote((abs / kBlocksDir).string()) << "/$name\n"
    << "exec " << shell_quote(engine.string()) << " train \"$scene\" --out \"$scene/" << kBlockTrainDir
    << "\"";
  for (const auto& a : o.train_args) s << " " << shell_quote(a);
  s << " --trace \"$scene/" << kBlockTrainDir << "/" << kBlockTrace << "\"";
  s << " >> \"$scene/train.log\" 2>&1\n";
  return s.str();
}

BlockTrainingReport train_blocks(const fs::path& dir, const fs::path& engine, const BlockTrainingOptions& o,
                                 const BlockProgress& progress) {
  const auto t0 = std::chrono::steady_clock::now();
  const std::vector<PartitionBlock> blocks = read_partition(dir, "train blocks").blocks;
  BlockTrainingReport r = o.executor == Executor::kLocal ? train_local(dir, engine, blocks, o, progress)
                                                         : train_slurm(dir, engine, blocks, o, progress);
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  throw_if_failed(r, o.executor == Executor::kLocal ? "local" : "slurm");
  return r;
}

}  // namespace litgs::host::partition
