// The one growth policy of the kernels' scratch and output arrays on the device: an array is replaced only
// when a request outgrows it, by one 1.5x larger (so arrays that follow a growing model, as densification
// grows it, are reallocated O(log n) times), and never made empty (Vulkan has no empty buffers).
#pragma once

#include <algorithm>
#include <cstddef>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "engine/buffer.h"
#include "engine/context.h"

namespace litgs::kernels {

// The capacity, in elements, that an array of `current` elements grows to when `needed` do not fit: 1.5x
// the current capacity, at least `needed`, at least 1.
inline size_t grown_capacity(size_t current, size_t needed) {
  return std::max({needed, current + current / 2, size_t{1}});
}

// Makes `array` hold at least `count` elements (at least 1): keeps it when it is large enough, else replaces
// it with a new array named `name` of grown_capacity() elements. The contents are not kept. The outgrown
// array is freed, or moved to `retired` (kept alive) when sequences recorded earlier may still use it.
template <class T>
void grow(engine::Context& context, std::unique_ptr<engine::DeviceArray<T>>& array, size_t count,
          const std::string& name, std::vector<std::unique_ptr<engine::DeviceArray<T>>>* retired = nullptr) {
  if (array && array->size() >= std::max<size_t>(count, 1)) return;
  const size_t capacity = grown_capacity(array ? array->size() : 0, count);
  if (array && retired) retired->push_back(std::move(array));
  array.reset();  // before allocating the new one: the old memory is free again first
  array = std::make_unique<engine::DeviceArray<T>>(context, name, capacity);
}

}  // namespace litgs::kernels
