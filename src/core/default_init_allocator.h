// An allocator whose value-less construction leaves trivial elements uninitialised, for large
// arrays that are written in full before they are read: std::vector<T, DefaultInitAllocator<T>>
// (n) then skips the pass that would clear them, and the fresh pages are first touched by the
// (parallel) code that fills them rather than by one thread's memset.
#pragma once

#include <memory>
#include <new>
#include <type_traits>
#include <utility>

namespace dispex {

template <class T>
class DefaultInitAllocator : public std::allocator<T> {
 public:
  using value_type = T;
  template <class U>
  struct rebind {
    using other = DefaultInitAllocator<U>;
  };
  DefaultInitAllocator() = default;
  template <class U>
  DefaultInitAllocator(const DefaultInitAllocator<U>&) noexcept {}  // NOLINT: implicit

  template <class U>
  void construct(U* p) noexcept(std::is_nothrow_default_constructible_v<U>) {
    ::new (static_cast<void*>(p)) U;
  }
  template <class U, class... Args>
  void construct(U* p, Args&&... args) {
    ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
  }
};

}  // namespace dispex
