#pragma once
// Compacting parallel attribute arrays (positions, normals, colours, ...) by one keep mask.
#include <cstdint>
#include <utility>
#include <vector>

#include "core/base/check.h"

namespace reconar {

// Keeps (*values)[i] where keep[i] != 0, in order. An empty `values` (an attribute the data does not
// have) stays empty; any other size must equal keep.size().
template <typename T>
void KeepMasked(const std::vector<uint8_t>& keep, std::vector<T>* values) {
  if (values->empty()) return;
  RECONAR_CHECK(values->size() == keep.size()) << "mask of " << keep.size() << " for " << values->size() << " values";
  size_t out = 0;
  for (size_t i = 0; i < keep.size(); ++i) {
    if (keep[i]) (*values)[out++] = std::move((*values)[i]);
  }
  values->resize(out);
}

}  // namespace reconar
