// 128-bit content keys (XXH3-128, libxxhash) for what a map was made from: inputs, options,
// and each face's share of them (incremental extraction).
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <type_traits>

namespace dispex {

struct Hash128 {
  std::uint64_t low = 0, high = 0;

  friend bool operator==(const Hash128&, const Hash128&) = default;
  // Lane-wise sum: the key of a set of items whatever their order (a multiset hash).
  Hash128& operator+=(const Hash128& other) {
    low += other.low;
    high += other.high;
    return *this;
  }
  std::string Hex() const;  // 32 lowercase hex digits, high half first
};

Hash128 HashBytes(std::span<const std::byte> bytes);

// Streaming XXH3-128: the same key as HashBytes of everything added, concatenated.
class Hasher {
 public:
  Hasher();
  ~Hasher();
  Hasher(const Hasher&) = delete;
  Hasher& operator=(const Hasher&) = delete;

  Hasher& Add(std::span<const std::byte> bytes);
  template <class T>
  requires std::is_trivially_copyable_v<T> Hasher& Add(const T& value) {
    return Add(std::as_bytes(std::span(&value, 1)));
  }
  template <class T>
  requires std::is_trivially_copyable_v<T> Hasher& AddArray(std::span<const T> values) {
    Add(values.size());
    return Add(std::as_bytes(values));
  }
  Hasher& Add(std::string_view text) {
    Add(text.size());
    return Add(std::as_bytes(std::span(text.data(), text.size())));
  }
  Hasher& Add(const Hash128& key) { return Add(key.low).Add(key.high); }
  Hash128 Digest() const;

 private:
  void* state_;  // XXH3_state_t
};

}  // namespace dispex
