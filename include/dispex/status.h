// Status and StatusOr: the one error channel for bad input and bad options.
//
// A failed Status carries a one-line message that names the file, the line or element, and
// what is wrong ("mesh.obj:12: face index 9 out of range (8 vertices)"). Its code says what
// kind of failure it is, so that a program branches on the code, never on the message text
// (the command line's exit status, the Python module's exception classes); where known, the
// file and the Ptex face it is about travel with it. Broken internal invariants are not
// Status errors: they are DISPEX_CHECK failures (src/core/check.h).
#pragma once

#include <cassert>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <utility>

namespace dispex {

enum class StatusCode : std::uint8_t {
  kOk,
  kFailed,           // any other failure
  kInvalidArgument,  // an option or argument out of range, of the wrong kind, or unknown
  kBadInput,         // a file or mesh that cannot be read or is malformed: path() names it
  kMismatch,         // inputs that do not belong together (no overlap, another sculpt's parts)
  kCheckFailed,      // a map that fails a check it was asked to pass (verify's bounds)
  kCancelled,        // cancelled (dispex/cancel.h)
  kOverBudget,       // estimated to need more memory than allowed (max_memory)
  kOutput,           // an output that cannot be written: path() names it
};
// "ok", "failed", "invalid_argument", "bad_input", "mismatch", "check_failed", "cancelled",
// "over_budget", "output".
std::string_view StatusCodeName(StatusCode code);

class [[nodiscard]] Status {
 public:
  Status() = default;
  static Status Ok() { return Status(); }
  static Status Error(std::string message) {
    return Error(StatusCode::kFailed, std::move(message));
  }
  static Status Error(StatusCode code, std::string message) {
    Status s;
    s.code_ = code == StatusCode::kOk ? StatusCode::kFailed : code;
    s.message_ = std::move(message);
    return s;
  }

  bool ok() const { return code_ == StatusCode::kOk; }
  StatusCode code() const { return code_; }
  const std::string& message() const { return message_; }
  const std::string& path() const { return path_; }  // the file it is about, or empty
  std::int64_t face() const { return face_; }        // the Ptex face it is about, or -1

  // Returns a copy whose message is "prefix: message" (for adding a file name or context).
  Status WithPrefix(const std::string& prefix) const {
    Status s = *this;
    if (!ok()) s.message_ = prefix + ": " + message_;
    return s;
  }
  // A copy with `code` where the failure's kind is not known yet (kFailed): the first, most
  // specific code set on the way up stays.
  Status WithCode(StatusCode code) const {
    Status s = *this;
    if (code_ == StatusCode::kFailed && code != StatusCode::kOk) s.code_ = code;
    return s;
  }
  // A copy naming the file it is about, unless a deeper call already named one.
  Status WithPath(const std::string& path) const {
    Status s = *this;
    if (!ok() && s.path_.empty()) s.path_ = path;
    return s;
  }
  // A copy naming the Ptex face it is about, unless a deeper call already named one.
  Status WithFace(std::int64_t face) const {
    Status s = *this;
    if (!ok() && s.face_ < 0) s.face_ = face;
    return s;
  }

 private:
  StatusCode code_ = StatusCode::kOk;
  std::string message_;
  std::string path_;
  std::int64_t face_ = -1;
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
