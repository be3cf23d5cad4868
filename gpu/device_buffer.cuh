// Owning buffers for the CUDA backend: device memory (cudaMalloc) and pinned
// host memory (cudaMallocHost) for the transfers of every iteration. Both only
// grow (with headroom), so that rigid steps of the same scene reuse them; a
// buffer's contents are discarded when it grows.
#pragma once

#include <cuda_runtime.h>

#include <cstddef>
#include <stdexcept>

#include "gpu/cuda_check.cuh"

namespace odemag::gpu {

// Capacity for a request of n elements: 25 % headroom, so that a slowly
// growing scene (bodies added one by one) does not reallocate every step.
inline size_t grown_capacity(size_t n) { return n + n / 4 + 16; }

template <class T>
class DeviceBuffer {
 public:
  DeviceBuffer() = default;
  ~DeviceBuffer() { release(); }
  DeviceBuffer(const DeviceBuffer&) = delete;
  DeviceBuffer& operator=(const DeviceBuffer&) = delete;

  // Room for n elements; the contents are undefined afterwards when it grew.
  void resize(size_t n) {
    if (n > capacity_) {
      release();
      const size_t capacity = grown_capacity(n);
      void* p = nullptr;
      ODEMAG_CUDA_CHECK(cudaMalloc(&p, capacity * sizeof(T)));
      data_ = static_cast<T*>(p);
      capacity_ = capacity;
    }
    size_ = n;
  }
  // Copies n elements from host memory (pinned or pageable) on the stream.
  void upload(const T* host, size_t n, cudaStream_t stream) {
    resize(n);
    if (n > 0)
      ODEMAG_CUDA_CHECK(cudaMemcpyAsync(data_, host, n * sizeof(T), cudaMemcpyHostToDevice, stream));
  }
  // Copies the first n elements to host memory on the stream (complete after
  // the stream is synchronised).
  void download(T* host, size_t n, cudaStream_t stream) const {
    if (n > size_) throw std::logic_error("DeviceBuffer::download past the end");
    if (n > 0)
      ODEMAG_CUDA_CHECK(cudaMemcpyAsync(host, data_, n * sizeof(T), cudaMemcpyDeviceToHost, stream));
  }
  T* data() { return data_; }
  const T* data() const { return data_; }
  size_t size() const { return size_; }
  size_t bytes() const { return size_ * sizeof(T); }

 private:
  // cudaFree synchronises the device, so no kernel still uses the memory.
  void release() {
    if (data_) (void)cudaFree(data_);  // no throwing from destructors
    data_ = nullptr;
    capacity_ = size_ = 0;
  }
  T* data_ = nullptr;
  size_t capacity_ = 0, size_ = 0;
};

template <class T>
class PinnedBuffer {
 public:
  PinnedBuffer() = default;
  ~PinnedBuffer() { release(); }
  PinnedBuffer(const PinnedBuffer&) = delete;
  PinnedBuffer& operator=(const PinnedBuffer&) = delete;

  // Room for n elements; the contents are undefined afterwards when it grew.
  // Call only while no copy from or to this buffer is pending.
  void resize(size_t n) {
    if (n > capacity_) {
      release();
      const size_t capacity = grown_capacity(n);
      void* p = nullptr;
      ODEMAG_CUDA_CHECK(cudaMallocHost(&p, capacity * sizeof(T)));
      data_ = static_cast<T*>(p);
      capacity_ = capacity;
    }
    size_ = n;
  }
  T& operator[](size_t i) { return data_[i]; }
  const T& operator[](size_t i) const { return data_[i]; }
  T* data() { return data_; }
  const T* data() const { return data_; }
  size_t size() const { return size_; }

 private:
  void release() {
    if (data_) (void)cudaFreeHost(data_);
    data_ = nullptr;
    capacity_ = size_ = 0;
  }
  T* data_ = nullptr;
  size_t capacity_ = 0, size_ = 0;
};

}  // namespace odemag::gpu
