// Names of enum values and the parsers that read them back, both from one table per enum
// (docs/ARCHITECTURE.md, "Names of enum values"): each `<Enum>Name` is EnumName over its table,
// each `Parse<Enum>` is ParseEnum over the same table, and every parser says what it expected in
// the same words: "unknown hole policy 'x' (expected fill, fail or zero)".
//
//   constexpr auto kHolePolicies = EnumTable<HolePolicy>({
//       {HolePolicy::kFill, "fill"}, {HolePolicy::kFail, "fail"}, {HolePolicy::kZero, "zero"}});
//   EnumName(kHolePolicies, HolePolicy::kFail)          // "fail"
//   ParseEnum(kHolePolicies, "hole policy", "zero")     // HolePolicy::kZero
#pragma once

#include <fmt/format.h>

#include <array>
#include <cstddef>
#include <string>
#include <string_view>

#include "dispex/status.h"

namespace dispex {

// Marks a row as an alias: a second spelling that ParseEnum reads, but that EnumName never
// gives and no message lists ("gray" for "grey").
inline constexpr bool kEnumAlias = true;

// One row of a table: a value and its name.
template <class E>
struct EnumNameRow {
  E value;
  std::string_view name;
  bool alias = false;
};

template <class E, std::size_t N>
using EnumNameTable = std::array<EnumNameRow<E>, N>;

// The table of the rows, in the order messages list them (the first row of a value is its
// name; later ones should be aliases).
template <class E, std::size_t N>
constexpr EnumNameTable<E, N> EnumTable(const EnumNameRow<E> (&rows)[N]) {
  EnumNameTable<E, N> table{};
  for (std::size_t i = 0; i < N; ++i) table[i] = rows[i];
  return table;
}

// The name of `value`; "?" for a value the table lacks (a cast from a bad number).
template <class E, std::size_t N>
constexpr std::string_view EnumName(const EnumNameTable<E, N>& table, E value) {
  for (const EnumNameRow<E>& row : table) {
    if (!row.alias && row.value == value) return row.name;
  }
  return "?";
}

namespace enum_names {

// Calls append with the pieces of the list of names: "a", "a or b", "a, b or c"; no aliases.
template <class E, std::size_t N, class Append>
constexpr void AppendNameList(const EnumNameTable<E, N>& table, Append&& append) {
  std::size_t listed = 0;
  for (const EnumNameRow<E>& row : table) listed += row.alias ? 0 : 1;
  std::size_t i = 0;
  for (const EnumNameRow<E>& row : table) {
    if (row.alias) continue;
    if (i > 0) append(i + 1 == listed ? std::string_view(" or ") : std::string_view(", "));
    append(row.name);
    ++i;
  }
}

template <const auto& kTable>
constexpr auto NameListChars() {
  constexpr std::size_t size = [] {
    std::size_t n = 0;
    AppendNameList(kTable, [&n](std::string_view piece) { n += piece.size(); });
    return n;
  }();
  std::array<char, size> chars{};
  std::size_t at = 0;
  AppendNameList(kTable, [&](std::string_view piece) {
    for (char c : piece) chars[at++] = c;
  });
  return chars;
}

template <const auto& kTable>
inline constexpr auto kNameListChars = NameListChars<kTable>();

}  // namespace enum_names

// The names a value may take, as messages list them: "fill, fail or zero" (no aliases).
template <class E, std::size_t N>
std::string EnumNameList(const EnumNameTable<E, N>& table) {
  std::string list;
  enum_names::AppendNameList(table, [&list](std::string_view piece) { list += piece; });
  return list;
}

// EnumNameList as a constant, for text built at compile time (the extract options' specs):
// EnumNameListConstant<kHolePolicies>() is "fill, fail or zero".
template <const auto& kTable>
constexpr std::string_view EnumNameListConstant() {
  return {enum_names::kNameListChars<kTable>.data(), enum_names::kNameListChars<kTable>.size()};
}

// The value named `text` (a name or an alias); otherwise an error naming `what` and listing
// the names: "unknown hole policy 'x' (expected fill, fail or zero)".
template <class E, std::size_t N>
StatusOr<E> ParseEnum(const EnumNameTable<E, N>& table, std::string_view what,
                      std::string_view text) {
  for (const EnumNameRow<E>& row : table) {
    if (row.name == text) return row.value;
  }
  return Status::Error(
      fmt::format("unknown {} '{}' (expected {})", what, text, EnumNameList(table)));
}

}  // namespace dispex
