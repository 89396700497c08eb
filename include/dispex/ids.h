// Typed element ids. Base faces, Ptex faces (sub-faces of n-gons), vertices and sculpt
// primitives are different things; mixing base-face and Ptex-face ids is this field's
// classic bug, so each gets its own type and mixing them does not compile.
#pragma once

#include <compare>
#include <cstdint>

namespace dispex {

template <class Tag>
struct Id {
  std::int32_t value = -1;

  constexpr Id() = default;
  constexpr explicit Id(std::int32_t v) : value(v) {}
  constexpr bool valid() const { return value >= 0; }
  constexpr auto operator<=>(const Id&) const = default;
};

using VertexId = Id<struct VertexTag>;
using BaseFaceId = Id<struct BaseFaceTag>;
using PtexFaceId = Id<struct PtexFaceTag>;
using SculptPrimId = Id<struct SculptPrimTag>;

}  // namespace dispex
