// `litgs-engine info [--json]`: the Vulkan devices and the facts the engine uses about the chosen one.
#include <CLI/CLI.hpp>
#include <iomanip>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>

#include "engine/context.h"
#include "tools/commands.h"
#include "tools/device_json.h"

namespace litgs::tools {
namespace {

struct InfoOptions {
  bool json = false;  // one JSON object instead of text
};

void print_text(const engine::DeviceInfo& d, const std::vector<engine::DeviceInfo>& all) {
  std::cout << "device        " << d.name << " (" << d.type << ", index " << d.index << " of " << all.size()
            << ")\n"
            << "driver        " << d.driver_name << ", " << d.driver_info << "\n"
            << "vulkan        " << d.api_version << "\n"
            << "subgroup      " << d.subgroup_size << " (range " << d.min_subgroup_size << ".."
            << d.max_subgroup_size << ", size control " << (d.compute_full_subgroups ? "yes" : "no") << ")\n"
            << "float atomics "
            << (d.float_atomic_add ? "yes (shaderBufferFloat32AtomicAdd)" : "no (CAS fallback)") << "\n"
            << "max storage buffer range " << d.max_storage_buffer_range / (1024 * 1024) << " MiB\n"
            << "max shared memory        " << d.max_compute_shared_memory_size / 1024 << " KiB\n"
            << "storage buffers / kernel " << d.max_per_stage_storage_buffers << "\n"
            << "timestamps    " << (d.timestamps ? "yes" : "no") << ", " << d.timestamp_period_ns
            << " ns/tick\n";
  for (size_t i = 0; i < d.memory_heaps.size(); ++i)
    std::cout << "heap " << i << "        " << std::fixed << std::setprecision(1)
              << static_cast<double>(d.memory_heaps[i].size_bytes) / (1024.0 * 1024.0 * 1024.0) << " GiB"
              << (d.memory_heaps[i].device_local ? " device-local" : "") << "\n";
  if (all.size() > 1) {
    std::cout << "other devices (choose with LITGS_DEVICE=<index or name>):\n";
    for (const auto& o : all)
      if (o.index != d.index) std::cout << "  " << o.index << ": " << o.name << " (" << o.type << ")\n";
  }
}

}  // namespace

void add_info_command(CLI::App& app) {
  auto options = std::make_shared<InfoOptions>();
  CLI::App* cmd = app.add_subcommand("info", "Print the Vulkan device the engine will use and its facts");
  cmd->add_flag("--json", options->json, "Print one JSON object");
  cmd->callback([options] {
    engine::Context context;
    const auto all = engine::Context::list_devices();
    if (options->json) {
      nlohmann::json j = device_json(context.info());
      j["devices"] = nlohmann::json::array();
      for (const auto& d : all)
        j["devices"].push_back({{"index", d.index}, {"name", d.name}, {"type", d.type}});
      std::cout << j.dump(2) << "\n";
    } else {
      print_text(context.info(), all);
    }
  });
}

}  // namespace litgs::tools
