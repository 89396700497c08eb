// Token-level scanning of text mesh files (OBJ, ASCII PLY): blanks, line continuations and
// numbers, shared so that every reader agrees on what a line and a number are.
//
// A "logical line" ends at a '\n' that is not preceded by a backslash (an optional '\r' may sit
// between the two): OBJ's `\` continuation joins the next physical line. Blanks are ' ', '\t',
// '\r' (so CRLF files read like LF files) and, where OBJ allows them, a continuation ("\\\n").
// Numbers: integers are parsed by hand (they dominate face lines); reals by fast_float, which
// rounds the decimal text straight to float (no double rounding).
#pragma once

#include <fast_float/fast_float.h>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <string>
#include <string_view>

namespace dispex::mesh {

inline bool IsBlank(char c) {
  return c == ' ' || c == '\t' || c == '\r';
}

// True when `p` starts a continuation: '\\' then an optional '\r' then '\n'. On success
// `length` is the number of bytes of the sequence (2 or 3).
inline bool IsContinuation(const char* p, const char* end, int& length) {
  if (p >= end || *p != '\\') return false;
  if (p + 1 < end && p[1] == '\n') {
    length = 2;
    return true;
  }
  if (p + 2 < end && p[1] == '\r' && p[2] == '\n') {
    length = 3;
    return true;
  }
  return false;
}

// True when `p` is a backslash that only blanks follow up to the end of the buffer: a
// continuation of the last line into nothing.
inline bool IsDanglingContinuation(const char* p, const char* end) {
  if (p >= end || *p != '\\') return false;
  for (++p; p < end; ++p) {
    if (!IsBlank(*p)) return false;
  }
  return true;
}

// Skips blanks and continuations; counts the physical lines crossed in `line`.
inline void SkipBlanks(const char*& p, const char* end, std::int64_t& line) {
  for (;;) {
    while (p < end && IsBlank(*p)) ++p;
    int length = 0;
    if (!IsContinuation(p, end, length)) return;
    p += length;
    ++line;
  }
}

// True when the '\n' at `newline` continues the logical line (a '\\' before it, with at most
// one '\r' between). `begin` bounds the look-back.
inline bool IsContinuedNewline(const char* begin, const char* newline) {
  const char* q = newline;
  if (q > begin && q[-1] == '\r') --q;
  return q > begin && q[-1] == '\\';
}

// Moves `p` just past the end of the current logical line (past its '\n', or to `end`),
// counting the physical newlines crossed in `line`. `begin` is where look-back may start.
inline void SkipLogicalLine(const char* begin, const char*& p, const char* end,
                            std::int64_t& line) {
  for (;;) {
    const void* hit = std::memchr(p, '\n', static_cast<std::size_t>(end - p));
    if (hit == nullptr) {
      p = end;
      return;
    }
    const char* nl = static_cast<const char*>(hit);
    ++line;
    p = nl + 1;
    if (!IsContinuedNewline(begin, nl)) return;
  }
}

// Calls visit(q) for every '\n' at q in [begin, end), in order. Scans 16 bytes at a time
// where SSE2 is available: much cheaper than a memchr call per line when lines are short.
template <class Visit>
inline void ForEachNewline(const char* begin, const char* end, Visit&& visit) {
  const char* p = begin;
#if defined(__SSE2__)
  const __m128i newline = _mm_set1_epi8('\n');
  for (; end - p >= 16; p += 16) {
    const __m128i bytes = _mm_loadu_si128(reinterpret_cast<const __m128i*>(p));
    unsigned mask = static_cast<unsigned>(_mm_movemask_epi8(_mm_cmpeq_epi8(bytes, newline)));
    while (mask != 0) {
      visit(p + __builtin_ctz(mask));
      mask &= mask - 1;
    }
  }
#endif
  for (; p < end; ++p) {
    if (*p == '\n') visit(p);
  }
}

// True when `c` may follow a number: a blank, a line end, a continuation backslash, a comment
// or the end of the buffer. (The OBJ face parser also accepts '/' itself.)
inline bool EndsToken(const char* p, const char* end) {
  return p == end || IsBlank(*p) || *p == '\n' || *p == '\\' || *p == '#';
}

// The token starting at `p` (up to a blank or line end, at most `limit` bytes), for messages.
// Bytes that are not printable ASCII are shown as '?', so a message stays one line.
inline std::string TokenForMessage(const char* p, const char* end, std::size_t limit = 24) {
  std::string out;
  while (p < end && !IsBlank(*p) && *p != '\n' && out.size() < limit) {
    unsigned char c = static_cast<unsigned char>(*p++);
    out.push_back(c >= 0x20 && c < 0x7f ? static_cast<char>(c) : '?');
  }
  if (p < end && !IsBlank(*p) && *p != '\n') out += "...";
  return out;
}

// The decimal digits that start the 8 bytes at `p` (all 8 must be readable): returns how many
// there are (0 to 8) and stores their value in `value`. One 64-bit word for the 8 bytes instead
// of a loop over them (face lines are mostly indices of 6 to 8 digits).
inline int LeadingDigits8(const char* p, std::uint32_t& value) {
  std::uint64_t word;
  std::memcpy(&word, p, 8);
  if constexpr (std::endian::native == std::endian::big) word = __builtin_bswap64(word);
  // Byte by byte, the first byte of the text the lowest: '0'..'9' become 0..9.
  const std::uint64_t t = word ^ 0x3030303030303030u;
  // A byte holds a digit when t <= 9, where neither t nor t + 6 reaches 16. A carry out of a
  // byte only happens for one that is not a digit and only changes the bytes after it.
  const std::uint64_t not_digit = (t | (t + 0x0606060606060606u)) & 0xf0f0f0f0f0f0f0f0u;
  const int n = not_digit == 0 ? 8 : __builtin_ctzll(not_digit) / 8;
  if (n == 0) return 0;
  // The n digits moved to the top bytes, zeros (leading digits 0) below, then combined in
  // pairs, fours and eights of bytes.
  std::uint64_t v = t << (8 * (8 - n));
  v = (v * 10 + (v >> 8)) & 0x00ff00ff00ff00ffu;
  v = (v * 100 + (v >> 16)) & 0x0000ffff0000ffffu;
  v = (v * 10000 + (v >> 32)) & 0xffffffffu;
  value = static_cast<std::uint32_t>(v);
  return n;
}

// kOutOfRange: an integer too large; kNotFinite: a real that is nan, inf or overflows.
enum class NumberResult { kOk, kNotNumber, kOutOfRange, kNotFinite };

// Parses a decimal integer with an optional sign at `p`. Does not check what follows.
// Values outside int64 (more than 18 digits) are kOutOfRange.
inline NumberResult ParseInt(const char*& p, const char* end, std::int64_t& value) {
  const char* q = p;
  bool negative = false;
  if (q < end && (*q == '-' || *q == '+')) {
    negative = *q == '-';
    ++q;
  }
  const char* digits = q;
  std::uint64_t v = 0;
  while (q < end && static_cast<unsigned char>(*q - '0') < 10) {
    v = v * 10 + static_cast<unsigned>(*q - '0');
    ++q;
    if (q - digits > 18) return NumberResult::kOutOfRange;
  }
  if (q == digits) return NumberResult::kNotNumber;
  value = negative ? -static_cast<std::int64_t>(v) : static_cast<std::int64_t>(v);
  p = q;
  return NumberResult::kOk;
}

// Parses a real number at `p` into `value` (float or double), correctly rounded. Accepts a
// leading '+'. Rejects nan/inf spellings and values that overflow the type (kNotFinite), so
// every accepted value is finite. Does not check what follows.
template <class T>
inline NumberResult ParseReal(const char*& p, const char* end, T& value) {
  const char* q = p;
  if (q < end && *q == '+') {
    ++q;
    if (q < end && *q == '-') return NumberResult::kNotNumber;
  }
  // fast_float accepts "nan"/"inf"; text mesh coordinates must be finite numbers.
  const char* first = q;
  if (first < end && *first == '-') ++first;
  if (first < end && (*first == 'n' || *first == 'N' || *first == 'i' || *first == 'I')) {
    return NumberResult::kNotFinite;
  }
  auto result = fast_float::from_chars(q, end, value);
  if (result.ec == std::errc::result_out_of_range) return NumberResult::kNotFinite;
  if (result.ec != std::errc() || result.ptr == q) return NumberResult::kNotNumber;
  if (!std::isfinite(value)) return NumberResult::kNotFinite;  // overflow gives inf
  p = result.ptr;
  return NumberResult::kOk;
}

}  // namespace dispex::mesh
