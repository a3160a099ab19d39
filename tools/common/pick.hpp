// Selecting elements of a vector by index: resamples of the bootstrap (tools/fidelity) and the
// kept samples of a table axis (tools/ref3d/sizing.cpp).
#pragma once

#include <cstddef>
#include <vector>

namespace statsim::tools {

/// The elements of `v` at `idx`, in that order (indices may repeat).
template <class T>
std::vector<T> pick(const std::vector<T>& v, const std::vector<std::size_t>& idx)
{
  std::vector<T> out;
  out.reserve(idx.size());
  for (std::size_t i : idx) out.push_back(v[i]);
  return out;
}

}  // namespace statsim::tools
