#include "kernels/spirv_registry.h"

#include <stdexcept>
#include <string>
#include <utility>

namespace litgs::kernels {
namespace detail {
// Defined in the generated spirv_registry_table.cc (cmake/EmbedShaders.cmake).
const std::vector<std::pair<std::string_view, std::span<const uint32_t>>>& spirv_table();
}  // namespace detail

std::span<const uint32_t> spirv(std::string_view name) {
  for (const auto& [key, words] : detail::spirv_table())
    if (key == name) return words;
  throw std::out_of_range("no embedded shader named '" + std::string(name) + "' (kernels/" +
                          std::string(name) + ".comp)");
}

std::vector<std::string_view> spirv_names() {
  std::vector<std::string_view> names;
  for (const auto& entry : detail::spirv_table()) names.push_back(entry.first);
  return names;
}

}  // namespace litgs::kernels
