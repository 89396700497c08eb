// A fixed-capacity append buffer in its own anonymous memory map.
//
// Why not std::vector: the parallel OBJ reader keeps one of these per chunk of the file and
// frees each as soon as it has been appended to the final array. Memory that comes from
// mmap goes back to the system at munmap, so the peak resident size stays near the final
// arrays; freed malloc blocks may stay in a thread's arena. Pages that are reserved but never
// written are never touched, so reserving a generous upper bound costs address space only.
#pragma once

#include <sys/mman.h>

#include <cstddef>
#include <type_traits>
#include <utility>

namespace dispex::mesh {

template <class T>
class ChunkBuffer {
  static_assert(std::is_trivially_copyable_v<T>);

 public:
  ChunkBuffer() = default;
  ChunkBuffer(ChunkBuffer&& other) noexcept
      : data_(std::exchange(other.data_, nullptr)),
        size_(std::exchange(other.size_, 0)),
        capacity_(std::exchange(other.capacity_, 0)) {}
  ChunkBuffer& operator=(ChunkBuffer&& other) noexcept {
    if (this != &other) {
      Release();
      data_ = std::exchange(other.data_, nullptr);
      size_ = std::exchange(other.size_, 0);
      capacity_ = std::exchange(other.capacity_, 0);
    }
    return *this;
  }
  ChunkBuffer(const ChunkBuffer&) = delete;
  ChunkBuffer& operator=(const ChunkBuffer&) = delete;
  ~ChunkBuffer() { Release(); }

  // Maps room for `capacity` elements. Returns false if the system refuses the mapping.
  bool Reserve(std::size_t capacity) {
    Release();
    if (capacity == 0) return true;
    void* p = ::mmap(nullptr, capacity * sizeof(T), PROT_READ | PROT_WRITE,
                     MAP_PRIVATE | MAP_ANONYMOUS | MAP_NORESERVE, -1, 0);
    if (p == MAP_FAILED) return false;
    data_ = static_cast<T*>(p);
    capacity_ = capacity;
    return true;
  }

  // The caller guarantees size() < capacity() (the reserve is an upper bound).
  void push_back(const T& value) { data_[size_++] = value; }
  bool full() const { return size_ == capacity_; }

  // Drops the last `n` elements (a face whose parse failed).
  void pop_back(std::size_t n) { size_ -= n; }

  const T* data() const { return data_; }
  const T* begin() const { return data_; }
  const T* end() const { return data_ + size_; }
  std::size_t size() const { return size_; }
  std::size_t capacity() const { return capacity_; }

  // Unmaps the memory (size and capacity become 0).
  void Release() {
    if (data_ != nullptr) ::munmap(data_, capacity_ * sizeof(T));
    data_ = nullptr;
    size_ = capacity_ = 0;
  }

 private:
  T* data_ = nullptr;
  std::size_t size_ = 0;
  std::size_t capacity_ = 0;
};

}  // namespace dispex::mesh
