#include "core/types/sequence_kind.h"

namespace sfc {

std::string_view SequenceName(SequenceKind kind) {
  switch (kind) {
    case SequenceKind::kJittered:
      return "jittered";
    case SequenceKind::kEqual:
      return "equal";
    case SequenceKind::kRandom:
      return "random";
    case SequenceKind::kVanDerCorput:
      return "vandercorput";
    case SequenceKind::kProgressive:
      return "progressive";
    case SequenceKind::kBlue:
      return "blue";
    case SequenceKind::kSobol:
      return "sobol";
  }
  return "jittered";
}

std::optional<SequenceKind> SequenceFromName(std::string_view name) {
  for (SequenceKind k : {SequenceKind::kJittered, SequenceKind::kEqual, SequenceKind::kRandom,
                         SequenceKind::kVanDerCorput, SequenceKind::kProgressive,
                         SequenceKind::kBlue, SequenceKind::kSobol}) {
    if (name == SequenceName(k)) return k;
  }
  return std::nullopt;
}

}  // namespace sfc
