// Names of enums in JSON, records and command lines: one ToString per enum, and from it the
// parser and the list of accepted values, so an enum's strings are written in one place.
// An enum E opts in by declaring, beside it, `const char* ToString(E)` and an array of all
// its values (e.g. kAllTerminations); the strings are stable: records and pages read them.
#pragma once

#include <array>
#include <cstddef>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>

namespace eol::analysis {

template <class E, std::size_t N>
std::optional<E> ParseEnum(std::string_view name, const std::array<E, N>& all) {
  for (E e : all)
    if (name == ToString(e)) return e;
  return std::nullopt;
}

// "a, b, c": the accepted names, for messages.
template <class E, std::size_t N>
std::string AcceptedNames(const std::array<E, N>& all) {
  std::string out;
  for (E e : all) out += (out.empty() ? "" : ", ") + std::string(ToString(e));
  return out;
}

// The value named `name`, or std::invalid_argument naming the field and the accepted values:
// "<field>: unknown value 'x' (accepted: a, b, c)".
template <class E, std::size_t N>
E ParseEnumOrThrow(std::string_view field, std::string_view name, const std::array<E, N>& all) {
  if (const std::optional<E> e = ParseEnum(name, all)) return *e;
  throw std::invalid_argument(std::string(field) + ": unknown value '" + std::string(name) +
                              "' (accepted: " + AcceptedNames(all) + ")");
}

}  // namespace eol::analysis
