// Output columns large enough to be worth 2 MiB pages. A column of a million
// samples is 8 MB: with 4 KiB pages its first write takes ~2 000 page faults
// (mesh_benchmark, 10^6 samples cold: 77 ms with 4 KiB pages, 64 ms with this
// advice). Where the kernel's transparent huge pages are in "madvise" mode
// (Debian's default), large columns ask for them.
//
// Thread-safety: ResizeColumn is as thread-safe as the vector it resizes.
#ifndef SFCSAMPLER_BASE_COLUMN_MEMORY_H_
#define SFCSAMPLER_BASE_COLUMN_MEMORY_H_

#include <cstddef>
#include <vector>

namespace sfc {

// Columns of at least this many bytes are backed by huge pages.
inline constexpr size_t kHugePageColumnBytes = size_t{4} << 20;

// Advises the kernel to back the whole 2 MiB pages inside [data, data +
// bytes) with huge pages (madvise MADV_HUGEPAGE). A hint: no effect where
// the kernel or the platform lacks them.
void AdviseHugePages(void* data, size_t bytes);

// column->reserve(rows), with the huge-page advice for a large column's new
// memory, before any of it is touched.
template <class T>
void ReserveColumn(std::vector<T>* column, size_t rows) {
  if (rows <= column->capacity()) return;
  column->reserve(rows);
  if (rows * sizeof(T) >= kHugePageColumnBytes) {
    AdviseHugePages(column->data(), column->capacity() * sizeof(T));
  }
}

// column->resize(rows), reserving as ReserveColumn does.
template <class T>
void ResizeColumn(std::vector<T>* column, size_t rows) {
  ReserveColumn(column, rows);
  column->resize(rows);
}

}  // namespace sfc

#endif  // SFCSAMPLER_BASE_COLUMN_MEMORY_H_
