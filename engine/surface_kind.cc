#include "engine/surface_kind.h"

#include <algorithm>

namespace sfc {

const SurfaceKind* SurfaceKinds::For(const std::optional<ModelSpec>& model) const {
  return Find([&model](const KindInfo& info) {
    if (!model) return info.formats.empty();
    return std::find(info.formats.begin(), info.formats.end(), model->format) != info.formats.end();
  });
}

const SurfaceKind* SurfaceKinds::Find(const std::function<bool(const KindInfo&)>& test) const {
  for (const auto& kind : kinds_) {
    if (test(kind->info())) return kind.get();
  }
  return nullptr;
}

}  // namespace sfc
