// Status propagation macros for absl::Status / absl::StatusOr.
//
// Abseil 20220623 (Debian bookworm) ships no status macros; these follow the
// semantics of the newer absl/status/status_macros.h. Thread-safe: stateless.
#ifndef SFCSAMPLER_BASE_STATUS_MACROS_H_
#define SFCSAMPLER_BASE_STATUS_MACROS_H_

#include "absl/status/status.h"
#include "absl/status/statusor.h"

#define SFC_STATUS_CONCAT_INNER_(a, b) a##b
#define SFC_STATUS_CONCAT_(a, b) SFC_STATUS_CONCAT_INNER_(a, b)

// Evaluates `expr` (an absl::Status) and returns it from the enclosing
// function when it is not OK.
#define RETURN_IF_ERROR(expr)                          \
  do {                                                 \
    ::absl::Status sfc_status_ = (expr);               \
    if (!sfc_status_.ok()) return sfc_status_;         \
  } while (false)

// ASSIGN_OR_RETURN(lhs, expr): evaluates `expr` (an absl::StatusOr<T>); on
// error returns its status, otherwise assigns (moves) the value to `lhs`,
// which may be a declaration such as `auto x`.
#define ASSIGN_OR_RETURN(lhs, expr) \
  SFC_ASSIGN_OR_RETURN_IMPL_(SFC_STATUS_CONCAT_(sfc_statusor_, __LINE__), lhs, expr)

#define SFC_ASSIGN_OR_RETURN_IMPL_(statusor, lhs, expr) \
  auto statusor = (expr);                               \
  if (!statusor.ok()) return std::move(statusor).status(); \
  lhs = std::move(statusor).value()

#endif  // SFCSAMPLER_BASE_STATUS_MACROS_H_
