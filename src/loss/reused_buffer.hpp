#pragma once
// Scratch arrays that a loss kernel needs at every training step.
#include <cstddef>
#include <vector>

namespace iesrgs::loss {

// n values of T that stay allocated for the thread's next call with the same Slot (any type that
// names the use): per-pixel arrays are megabytes at HR, which a fresh vector would page in, and
// clear, at every step. The contents are whatever the last call left.
template <typename T, typename Slot>
T* reused_buffer(size_t n) {
  thread_local std::vector<T> buffer;
  if (buffer.size() < n) buffer.resize(n);
  return buffer.data();
}

}  // namespace iesrgs::loss
