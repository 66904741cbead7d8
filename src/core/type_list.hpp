// A list of types and one vector per type of it: the registries of boundary geometries
// (model/environment.hpp, SurfaceGeometries) and of their config tables (io/surface_tables.hpp,
// SurfaceTables) are such lists, and the Environment and the config keep one vector of
// specifications per entry.
#pragma once

#include <cstddef>
#include <tuple>
#include <type_traits>
#include <vector>

namespace kairos {

// How many of Ts are T.
template <class T, class... Ts>
inline constexpr std::size_t count_of = (std::size_t{0} + ... + std::size_t{std::is_same_v<T, Ts>});

template <class... Types>
struct TypeList {
  static_assert(((count_of<Types, Types...> == 1) && ...),
                "a TypeList holds each type once (index() finds a type by its place)");
  // f(std::type_identity<T>{}) for each type T, in order.
  template <class F>
  static void each(F&& f) {
    (f(std::type_identity<Types>{}), ...);
  }
  template <class T>
  static constexpr std::size_t index() {
    constexpr bool match[] = {std::is_same_v<T, Types>...};
    for (std::size_t i = 0; i < sizeof...(Types); ++i)
      if (match[i]) return i;
    return sizeof...(Types);
  }
};

// One std::vector<Element<T>> per type T of `List`: of<T>().
template <class List, template <class> class Element>
struct VectorsOf;

template <template <class> class Element, class... Types>
struct VectorsOf<TypeList<Types...>, Element> {
  std::tuple<std::vector<Element<Types>>...> lists;

  template <class T>
  std::vector<Element<T>>& of() {
    return std::get<TypeList<Types...>::template index<T>()>(lists);
  }
  template <class T>
  const std::vector<Element<T>>& of() const {
    return std::get<TypeList<Types...>::template index<T>()>(lists);
  }
  bool empty() const {
    return std::apply([](const auto&... list) { return (list.empty() && ...); }, lists);
  }
  bool operator==(const VectorsOf&) const = default;
};

}  // namespace kairos
