#include "python/bindings/memory_models.h"

#include <utility>

#include "absl/strings/str_format.h"

namespace sfc::python {

std::string MemoryModelSource::Hold(ModelFormat format, std::string bytes, std::string name) {
  StoredModel model;
  model.format = format;
  model.sha256 = Sha256Hex(bytes);
  model.bytes = std::make_shared<const std::string>(std::move(bytes));
  model.name = std::move(name);
  std::string spec = model.Spec();
  absl::MutexLock lock(&mu_);
  Held& held = held_[spec];
  if (held.holds == 0) held.model = std::move(model);
  ++held.holds;
  return spec;
}

void MemoryModelSource::Release(const std::string& spec) {
  absl::MutexLock lock(&mu_);
  auto it = held_.find(spec);
  if (it != held_.end() && --it->second.holds <= 0) held_.erase(it);
}

absl::StatusOr<StoredModel> MemoryModelSource::Resolve(const ModelSpec& spec) const {
  if (spec.sha256.empty()) return files_.Resolve(spec);
  {
    absl::MutexLock lock(&mu_);
    auto it =
        held_.find(absl::StrFormat("%s:sha256=%s", ModelFormatName(spec.format), spec.sha256));
    if (it != held_.end()) return it->second.model;
  }
  return absl::NotFoundError(absl::StrFormat(
      "%s names a model this process does not hold; pass the mesh arrays (mesh=...) or a file's "
      "path, or use a Client for a server's uploaded models",
      spec.reference));
}

}  // namespace sfc::python
