// Plain values and arrays appended to a byte string and taken back in the same order: the
// layout of the cache files a run keeps for the next (the sculpt's match, the search distance's
// rays). Native byte order: a cache file is read on the machine that wrote it.
#pragma once

#include <cstdint>
#include <cstring>
#include <span>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

namespace dispex {

template <class T>
requires std::is_trivially_copyable_v<T>
void Append(std::string& out, const T& value) {
  out.append(reinterpret_cast<const char*>(&value), sizeof(T));
}

template <class T>
requires std::is_trivially_copyable_v<T>
void AppendArray(std::string& out, std::span<const T> values) {
  Append(out, std::uint64_t{values.size()});
  out.append(reinterpret_cast<const char*>(values.data()), values.size() * sizeof(T));
}
template <class T>
requires std::is_trivially_copyable_v<T>
void AppendArray(std::string& out, const std::vector<T>& values) {
  AppendArray(out, std::span<const T>(values));
}

// Reads what Append wrote at `at`, advancing it; false past the end.
template <class T>
requires std::is_trivially_copyable_v<T>
bool Take(std::string_view bytes, std::size_t& at, T& value) {
  if (bytes.size() - at < sizeof(T)) return false;
  std::memcpy(&value, bytes.data() + at, sizeof(T));
  at += sizeof(T);
  return true;
}

template <class T>
requires std::is_trivially_copyable_v<T>
bool TakeArray(std::string_view bytes, std::size_t& at, std::vector<T>& values) {
  std::uint64_t count = 0;
  if (!Take(bytes, at, count) || count > (bytes.size() - at) / sizeof(T)) return false;
  values.resize(count);
  std::memcpy(values.data(), bytes.data() + at, count * sizeof(T));
  at += count * sizeof(T);
  return true;
}

// Like TakeArray, but the values stay in `bytes` (a mapped file): false where they would not be
// aligned for T there.
template <class T>
requires std::is_trivially_copyable_v<T>
bool TakeView(std::string_view bytes, std::size_t& at, std::span<const T>& values) {
  std::uint64_t count = 0;
  if (!Take(bytes, at, count) || count > (bytes.size() - at) / sizeof(T) ||
      reinterpret_cast<std::uintptr_t>(bytes.data() + at) % alignof(T) != 0) {
    return false;
  }
  values = std::span<const T>(reinterpret_cast<const T*>(bytes.data() + at), count);
  at += count * sizeof(T);
  return true;
}

}  // namespace dispex
