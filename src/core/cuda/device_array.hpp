#pragma once
// Device memory owned by host code: the CUDA kernels' grow-only buffers, and copies of host
// arrays for callers that hold their data on the host (tests, benchmarks).
#include <cuda_runtime.h>

#include <cstddef>
#include <utility>
#include <vector>

#include "core/cuda/check.hpp"

namespace iesrgs::cuda {

template <typename T>
class DeviceArray {
 public:
  DeviceArray() = default;
  explicit DeviceArray(const std::vector<T>& host) { upload(host); }
  ~DeviceArray() { cudaFree(data_); }
  DeviceArray(DeviceArray&& other) noexcept
      : data_(std::exchange(other.data_, nullptr)),
        size_(std::exchange(other.size_, 0)),
        capacity_(std::exchange(other.capacity_, 0)) {}
  DeviceArray& operator=(DeviceArray&& other) noexcept {
    std::swap(data_, other.data_);
    std::swap(size_, other.size_);
    std::swap(capacity_, other.capacity_);
    return *this;
  }

  // Room for `size` elements. Grows by half again as much as asked, so that a scene growing by
  // densification does not reallocate every frame; contents are kept only while it does not
  // grow.
  T* reserve(size_t size) {
    if (size > capacity_) {
      check(cudaFree(data_), "cudaFree");
      data_ = nullptr;
      capacity_ = 0;
      const size_t grown = size + size / 2;
      check(cudaMalloc(&data_, grown * sizeof(T)), "cudaMalloc");
      capacity_ = grown;
    }
    size_ = size;
    return data_;
  }
  // Copies host into the array, which then holds host.size() elements.
  void upload(const std::vector<T>& host) {
    reserve(host.size());
    if (!host.empty())
      check(cudaMemcpy(data_, host.data(), host.size() * sizeof(T), cudaMemcpyHostToDevice),
            "copy to the device");
  }
  // The array's elements (as many as last reserved or uploaded), copied to the host.
  std::vector<T> download() const {
    std::vector<T> host(size_);
    if (size_ > 0)
      check(cudaMemcpy(host.data(), data_, size_ * sizeof(T), cudaMemcpyDeviceToHost),
            "copy to the host");
    return host;
  }

  T* data() const { return data_; }
  size_t size() const { return size_; }

 private:
  T* data_ = nullptr;
  size_t size_ = 0, capacity_ = 0;
};

}  // namespace iesrgs::cuda
