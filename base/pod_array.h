// A growable array of trivially copyable values whose storage grows and
// shrinks by realloc. For large arrays glibc serves realloc with mremap: the
// pages move, nothing is copied, and the new tail takes no memory until it is
// written. So a curve tree being built holds about the bytes of its leaves,
// never an old and a new copy at once as std::vector's growth does, which is
// what lets the leaf budget bound a build's peak memory (issue 10).
//
// Thread-compatible. Allocation failure throws std::bad_alloc, like
// std::vector.
#ifndef SFCSAMPLER_BASE_POD_ARRAY_H_
#define SFCSAMPLER_BASE_POD_ARRAY_H_

#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <new>
#include <type_traits>
#include <utility>

namespace sfc {

template <typename T>
class PodArray {
  static_assert(std::is_trivially_copyable_v<T>, "PodArray moves its bytes with realloc");

 public:
  PodArray() = default;
  ~PodArray() { std::free(data_); }
  PodArray(const PodArray& other) { *this = other; }
  PodArray& operator=(const PodArray& other) {
    if (this != &other) {
      size_ = 0;
      Reallocate(other.size_);
      if (other.size_ > 0) std::memcpy(data_, other.data_, other.size_ * sizeof(T));
      size_ = other.size_;
    }
    return *this;
  }
  PodArray(PodArray&& other) noexcept { *this = std::move(other); }
  PodArray& operator=(PodArray&& other) noexcept {
    if (this != &other) {
      std::free(data_);
      data_ = std::exchange(other.data_, nullptr);
      size_ = std::exchange(other.size_, 0);
      capacity_ = std::exchange(other.capacity_, 0);
    }
    return *this;
  }

  size_t size() const { return size_; }
  size_t capacity() const { return capacity_; }
  bool empty() const { return size_ == 0; }
  T* data() { return data_; }
  const T* data() const { return data_; }
  T& operator[](size_t i) { return data_[i]; }
  const T& operator[](size_t i) const { return data_[i]; }
  T* begin() { return data_; }
  T* end() { return data_ + size_; }
  const T* begin() const { return data_; }
  const T* end() const { return data_ + size_; }
  T& back() { return data_[size_ - 1]; }
  const T& back() const { return data_[size_ - 1]; }

  void clear() { size_ = 0; }
  void reserve(size_t n) {
    if (n > capacity_) Reallocate(n);
  }
  void push_back(const T& value) {
    if (size_ == capacity_) Reallocate(std::max<size_t>(16, capacity_ + capacity_ / 2));
    data_[size_++] = value;
  }
  // Gives back the unused tail (in place for large arrays).
  void shrink_to_fit() {
    if (capacity_ > size_) Reallocate(size_);
  }

 private:
  // REQUIRES: n >= size_.
  void Reallocate(size_t n) {
    if (n == 0) {
      std::free(data_);
      data_ = nullptr;
      capacity_ = 0;
      return;
    }
    void* grown = std::realloc(data_, n * sizeof(T));
    if (grown == nullptr) throw std::bad_alloc();
    data_ = static_cast<T*>(grown);
    capacity_ = n;
  }

  T* data_ = nullptr;
  size_t size_ = 0;
  size_t capacity_ = 0;
};

}  // namespace sfc

#endif  // SFCSAMPLER_BASE_POD_ARRAY_H_
