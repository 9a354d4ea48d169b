// The SPIR-V of every kernels/**/*.comp, compiled by glslang at build time and embedded in the library.
#pragma once

#include <cstdint>
#include <span>
#include <string_view>
#include <vector>

namespace litgs::kernels {

// SPIR-V words of the shader at kernels/<name>.comp, e.g. spirv("sort/radix_scatter").
// Throws std::out_of_range naming the shader when there is none.
std::span<const uint32_t> spirv(std::string_view name);

// Names of all embedded shaders.
std::vector<std::string_view> spirv_names();

}  // namespace litgs::kernels
