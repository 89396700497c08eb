// DISPEX_CHECK*: invariants that hold unless dispex itself has a bug. On failure they print
// the expression, the values involved and the location, then abort. Never use them for
// bytes read from a file or for user options: those are Status errors.
#pragma once

#include <fmt/format.h>

#include <cstdio>
#include <cstdlib>

namespace dispex::detail {
[[noreturn]] inline void CheckFailed(const char* file, int line, const std::string& what) {
  std::fprintf(stderr, "dispex: internal error at %s:%d: %s\n", file, line, what.c_str());
  std::fflush(stderr);
  std::abort();
}
}  // namespace dispex::detail

#define DISPEX_CHECK(cond)                                                          \
  do {                                                                              \
    if (!(cond)) [[unlikely]]                                                       \
      ::dispex::detail::CheckFailed(__FILE__, __LINE__, "CHECK(" #cond ") failed"); \
  } while (0)

#define DISPEX_CHECK_OP(a, op, b)                                                              \
  do {                                                                                         \
    const auto& dispex_a_ = (a);                                                               \
    const auto& dispex_b_ = (b);                                                               \
    if (!(dispex_a_ op dispex_b_)) [[unlikely]]                                                \
      ::dispex::detail::CheckFailed(                                                           \
          __FILE__, __LINE__,                                                                  \
          fmt::format("CHECK({} " #op " {}) failed: {} vs {}", #a, #b, dispex_a_, dispex_b_)); \
  } while (0)

#define DISPEX_CHECK_EQ(a, b) DISPEX_CHECK_OP(a, ==, b)
#define DISPEX_CHECK_NE(a, b) DISPEX_CHECK_OP(a, !=, b)
#define DISPEX_CHECK_LT(a, b) DISPEX_CHECK_OP(a, <, b)
#define DISPEX_CHECK_LE(a, b) DISPEX_CHECK_OP(a, <=, b)
#define DISPEX_CHECK_GT(a, b) DISPEX_CHECK_OP(a, >, b)
#define DISPEX_CHECK_GE(a, b) DISPEX_CHECK_OP(a, >=, b)
