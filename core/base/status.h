#pragma once
// Status / Result<T>: the error channel of every core function that can fail on input.
// Messages name the file (or object) and the reason, e.g. "photos/a.jpg: truncated JPEG data".
#include <optional>
#include <string>
#include <string_view>
#include <utility>

#include "core/base/check.h"

namespace reconar {

enum class StatusCode {
  kOk = 0,
  kInvalidArgument,    // the caller passed something unusable (bad option, bad size)
  kNotFound,           // a file or entity that should exist does not
  kIoError,            // the OS refused a read or write (permissions, full disk, ...)
  kCorruptData,        // the bytes exist but do not parse as the format they claim
  kUnsupported,        // a valid input we deliberately do not handle (e.g. CMYK JPEG)
  kResourceExhausted,  // a configured limit (arena, pixel budget) would be exceeded
  kNumericFailure,     // a factorisation failed or a NaN/Inf appeared
  kFailedPrecondition, // the input is valid but cannot yield a result (e.g. unrelated photos)
  kInternal,           // a bug: an invariant did not hold
};

const char* StatusCodeName(StatusCode code);

class [[nodiscard]] Status {
 public:
  Status() = default;
  Status(StatusCode code, std::string message) : code_(code), message_(std::move(message)) {}

  static Status Ok() { return Status(); }
  bool ok() const { return code_ == StatusCode::kOk; }
  StatusCode code() const { return code_; }
  const std::string& message() const { return message_; }
  std::string ToString() const;

  // Returns a copy whose message is "context: message" (e.g. prefixing a file name); an ok status
  // is returned as it is, without allocating (per-frame option checks call this).
  Status WithContext(std::string_view context) const;

 private:
  StatusCode code_ = StatusCode::kOk;
  std::string message_;
};

Status InvalidArgument(std::string message);
Status NotFound(std::string message);
Status IoError(std::string message);
Status CorruptData(std::string message);
Status Unsupported(std::string message);
Status ResourceExhausted(std::string message);
Status NumericFailure(std::string message);
Status FailedPrecondition(std::string message);
Status Internal(std::string message);
// "path: reason" with the given code.
Status FileError(StatusCode code, const std::string& path, const std::string& reason);

template <typename T>
class [[nodiscard]] Result {
 public:
  Result(T value) : value_(std::move(value)) {}  // NOLINT: implicit by design
  Result(Status status) : status_(std::move(status)) {  // NOLINT: implicit by design
    RECONAR_CHECK(!status_.ok()) << "Result constructed from an OK status without a value";
  }

  bool ok() const { return value_.has_value(); }
  const Status& status() const { return status_; }

  T& value() & {
    RECONAR_CHECK(ok()) << status_.ToString();
    return *value_;
  }
  const T& value() const& {
    RECONAR_CHECK(ok()) << status_.ToString();
    return *value_;
  }
  T&& value() && {
    RECONAR_CHECK(ok()) << status_.ToString();
    return std::move(*value_);
  }
  T& operator*() & { return value(); }
  const T& operator*() const& { return value(); }
  T* operator->() { return &value(); }
  const T* operator->() const { return &value(); }

 private:
  std::optional<T> value_;
  Status status_;
};

}  // namespace reconar

#define RECONAR_STATUS_CONCAT_INNER(a, b) a##b
#define RECONAR_STATUS_CONCAT(a, b) RECONAR_STATUS_CONCAT_INNER(a, b)

#define RECONAR_RETURN_IF_ERROR(expr)              \
  do {                                             \
    ::reconar::Status reconar_status_ = (expr);    \
    if (!reconar_status_.ok()) return reconar_status_; \
  } while (0)

#define RECONAR_ASSIGN_OR_RETURN_IMPL(tmp, lhs, expr) \
  auto tmp = (expr);                                  \
  if (!tmp.ok()) return tmp.status();                 \
  lhs = std::move(tmp).value()

#define RECONAR_ASSIGN_OR_RETURN(lhs, expr) \
  RECONAR_ASSIGN_OR_RETURN_IMPL(RECONAR_STATUS_CONCAT(reconar_result_, __LINE__), lhs, expr)
