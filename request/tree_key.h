// A stable identity for curve trees: the canonical text of everything that
// shapes a tree, and a 64-bit FNV-1a hash of it that does not change between
// runs, machines or builds (absl::Hash would). Thread-safe, pure functions.
#ifndef SFCSAMPLER_REQUEST_TREE_KEY_H_
#define SFCSAMPLER_REQUEST_TREE_KEY_H_

#include <cstdint>
#include <string>

#include "core/types/tree_options.h"

namespace sfc {

struct TreeKey {
  std::string canonical;  // "version=...|surface=...|density=...|curve=...|..."
  uint64_t hash = 0;      // FNV-1a 64 of canonical

  // 16 lowercase hex digits of `hash`.
  std::string Hex() const;
  // The key of the same tree at `grade`.
  std::string HexWithGrade(int grade) const;
};

// REQUIRES: canonical surface and density specs and resolved options.
TreeKey MakeTreeKey(const std::string& canonical_surface, const std::string& canonical_density,
                    const CurveTreeOptions& options);

uint64_t Fnv1a64(const std::string& text);

}  // namespace sfc

#endif  // SFCSAMPLER_REQUEST_TREE_KEY_H_
