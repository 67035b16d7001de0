// field_count.h — the number of fields of an aggregate struct, at compile time, so that a struct whose
// fields are listed by hand (visitFields of the settings) fails the build when a field is added.
#pragma once
#include <cstddef>
#include <utility>

namespace caustica {

namespace detail {
struct AnyField {
  template <class T>
  operator T() const;  // declared only: used in unevaluated brace-initialisations
};
template <class T, class... A>
constexpr auto bracesFrom(int) -> decltype(T{std::declval<A>()...}, true) { return true; }
template <class T, class... A>
constexpr bool bracesFrom(...) { return false; }
}  // namespace detail

// How many fields T{...} takes: the largest n for which T{x1, ..., xn} compiles (T an aggregate
// without base classes; a nested struct counts as one field).
template <class T, class... A>
constexpr std::size_t fieldCount() {
  if constexpr (!detail::bracesFrom<T, A...>(0)) return sizeof...(A) - 1;
  else return fieldCount<T, A..., detail::AnyField>();
}

}  // namespace caustica
