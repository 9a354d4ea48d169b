// DeviceInfo as JSON, for `info --json` and the benchmarks' reports.
#pragma once

#include <nlohmann/json.hpp>

#include "engine/context.h"

namespace litgs::tools {

inline nlohmann::json device_json(const engine::DeviceInfo& d) {
  nlohmann::json heaps = nlohmann::json::array();
  for (const auto& h : d.memory_heaps)
    heaps.push_back({{"size_bytes", h.size_bytes}, {"device_local", h.device_local}});
  return {{"index", d.index},
          {"name", d.name},
          {"type", d.type},
          {"driver_name", d.driver_name},
          {"driver_info", d.driver_info},
          {"api_version", d.api_version},
          {"vendor_id", d.vendor_id},
          {"subgroup_size", d.subgroup_size},
          {"min_subgroup_size", d.min_subgroup_size},
          {"max_subgroup_size", d.max_subgroup_size},
          {"subgroup_size_control", d.compute_full_subgroups},
          {"float_atomic_add", d.float_atomic_add},
          {"max_storage_buffer_range", d.max_storage_buffer_range},
          {"max_memory_allocation_size", d.max_memory_allocation_size},
          {"max_compute_shared_memory_size", d.max_compute_shared_memory_size},
          {"timestamps", d.timestamps},
          {"timestamp_period_ns", d.timestamp_period_ns},
          {"memory_heaps", heaps}};
}

}  // namespace litgs::tools
