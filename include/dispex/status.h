// Status and StatusOr: the one error channel for bad input and bad options.
//
// A failed Status carries a one-line message that names the file, the line or element, and
// what is wrong ("mesh.obj:12: face index 9 out of range (8 vertices)"). Broken internal
// invariants are not Status errors: they are DISPEX_CHECK failures (src/core/check.h).
#pragma once

#include <cassert>
#include <optional>
#include <string>
#include <utility>

namespace dispex {

class [[nodiscard]] Status {
 public:
  Status() = default;
  static Status Ok() { return Status(); }
  static Status Error(std::string message) {
    Status s;
    s.ok_ = false;
    s.message_ = std::move(message);
    return s;
  }

  bool ok() const { return ok_; }
  const std::string& message() const { return message_; }

  // Returns a copy whose message is "prefix: message" (for adding a file name or context).
  Status WithPrefix(const std::string& prefix) const {
    return ok_ ? *this : Error(prefix + ": " + message_);
  }

 private:
  bool ok_ = true;
  std::string message_;
};

// Either a value or a failed Status. Accessing the value of a failed StatusOr is a
// programming error (asserted).
template <class T>
class [[nodiscard]] StatusOr {
 public:
  StatusOr(T value) : value_(std::move(value)) {}         // NOLINT: implicit by design
  StatusOr(Status status) : status_(std::move(status)) {  // NOLINT: implicit by design
    assert(!status_.ok() && "StatusOr built from an OK status without a value");
  }

  bool ok() const { return value_.has_value(); }
  const Status& status() const { return status_; }

  T& value() & {
    assert(ok());
    return *value_;
  }
  const T& value() const& {
    assert(ok());
    return *value_;
  }
  T&& value() && {
    assert(ok());
    return std::move(*value_);
  }
  T* operator->() { return &value(); }
  const T* operator->() const { return &value(); }
  T& operator*() & { return value(); }
  const T& operator*() const& { return value(); }

 private:
  std::optional<T> value_;
  Status status_;
};

}  // namespace dispex

#define DISPEX_STATUS_CONCAT_INNER(a, b) a##b
#define DISPEX_STATUS_CONCAT(a, b) DISPEX_STATUS_CONCAT_INNER(a, b)

// Returns the Status of `expr` from the enclosing function if it failed.
#define DISPEX_RETURN_IF_ERROR(expr)                 \
  do {                                               \
    ::dispex::Status dispex_status_ = (expr);        \
    if (!dispex_status_.ok()) return dispex_status_; \
  } while (0)

// `lhs = value of expr`, or returns its Status from the enclosing function.
#define DISPEX_ASSIGN_OR_RETURN(lhs, expr) \
  DISPEX_ASSIGN_OR_RETURN_IMPL(DISPEX_STATUS_CONCAT(dispex_statusor_, __LINE__), lhs, expr)
#define DISPEX_ASSIGN_OR_RETURN_IMPL(tmp, lhs, expr) \
  auto tmp = (expr);                                 \
  if (!tmp.ok()) return tmp.status();                \
  lhs = std::move(tmp).value()
