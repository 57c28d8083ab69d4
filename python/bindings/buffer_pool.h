// Output columns that NumPy hands back when Python frees their arrays, kept
// for the engine's next call: a warm loop of equal-sized calls refills memory
// it already owns instead of having the kernel fault in and zero fresh pages
// (issue 34: a third of a warm 4 M-sample call's time was the kernel's).
// Bounded in bytes; the buffer returned longest ago goes first.
//
// Thread-safety: every method may be called from any thread.
#ifndef SFCSAMPLER_PYTHON_BINDINGS_BUFFER_POOL_H_
#define SFCSAMPLER_PYTHON_BINDINGS_BUFFER_POOL_H_

#include <cstddef>
#include <cstdint>
#include <list>
#include <mutex>
#include <variant>
#include <vector>

#include "base/column_memory.h"

namespace sfc::python {

class BufferPool {
 public:
  // Buffers smaller than this come back from malloc's heap without faults
  // (module.cc keeps allocations up to 32 MiB there); they are not pooled.
  static constexpr size_t kMinPooledBytes = size_t{1} << 20;

  explicit BufferPool(uint64_t max_bytes) : max_bytes_(max_bytes) {}

  // An empty vector with capacity for at least `n` values: the smallest
  // pooled buffer of n to 2n values, else a new reservation (ReserveColumn).
  template <class T>
  std::vector<T> Take(size_t n) {
    std::vector<T> out;
    if (n * sizeof(T) >= kMinPooledBytes) {
      std::lock_guard<std::mutex> lock(mu_);
      auto best = held_.end();
      for (auto it = held_.begin(); it != held_.end(); ++it) {
        const auto* v = std::get_if<std::vector<T>>(&*it);
        if (v == nullptr || v->capacity() < n || v->capacity() > 2 * n) continue;
        if (best == held_.end() || v->capacity() < std::get<std::vector<T>>(*best).capacity()) {
          best = it;
        }
      }
      if (best != held_.end()) {
        out = std::move(std::get<std::vector<T>>(*best));
        held_bytes_ -= out.capacity() * sizeof(T);
        held_.erase(best);
      }
    }
    ReserveColumn(&out, n);
    return out;
  }

  // Keeps `v`'s memory for a later Take, unless it is small or alone beyond
  // the bound; older buffers go to stay within it.
  template <class T>
  void Give(std::vector<T>&& v) {
    const uint64_t bytes = v.capacity() * sizeof(T);
    if (bytes < kMinPooledBytes || bytes > max_bytes_) return;
    v.clear();
    std::lock_guard<std::mutex> lock(mu_);
    while (held_bytes_ + bytes > max_bytes_) {
      std::visit([&](auto& old) { held_bytes_ -= old.capacity() * sizeof(old[0]); }, held_.front());
      held_.pop_front();
    }
    held_.emplace_back(std::move(v));
    held_bytes_ += bytes;
  }

 private:
  using Buffer = std::variant<std::vector<double>, std::vector<float>, std::vector<uint64_t>,
                              std::vector<uint32_t>>;
  const uint64_t max_bytes_;
  std::mutex mu_;
  std::list<Buffer> held_;  // oldest first
  uint64_t held_bytes_ = 0;
};

}  // namespace sfc::python

#endif  // SFCSAMPLER_PYTHON_BINDINGS_BUFFER_POOL_H_
