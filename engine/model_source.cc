#include "engine/model_source.h"

namespace sfc {

absl::StatusOr<StoredModel> FileModelSource::Resolve(const ModelSpec& spec) const {
  return ReadModelFile(spec, max_bytes_);
}

}  // namespace sfc
