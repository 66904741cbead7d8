// A list of boundary geometries (components of boundaries/, each with `using Spec`, one
// surface's specification) and the specifications of each: the model's registry of
// geometries is one such list (SurfaceGeometries, model/environment.hpp).
#pragma once

#include <cstddef>
#include <tuple>
#include <type_traits>
#include <vector>

namespace kairos {

template <class... Geometries>
struct GeometryList {
  // f(std::type_identity<G>{}) for each geometry G, in order.
  template <class F>
  static void each(F&& f) {
    (f(std::type_identity<Geometries>{}), ...);
  }
  template <class G>
  static constexpr std::size_t index() {
    constexpr bool match[] = {std::is_same_v<G, Geometries>...};
    for (std::size_t i = 0; i < sizeof...(Geometries); ++i)
      if (match[i]) return i;
    return sizeof...(Geometries);
  }

  // The specifications of every geometry's surfaces: of<PlaneWalls<3>>().
  struct Specs {
    std::tuple<std::vector<typename Geometries::Spec>...> lists;

    template <class G>
    std::vector<typename G::Spec>& of() {
      return std::get<index<G>()>(lists);
    }
    template <class G>
    const std::vector<typename G::Spec>& of() const {
      return std::get<index<G>()>(lists);
    }
    bool empty() const {
      return std::apply([](const auto&... list) { return (list.empty() && ...); }, lists);
    }
  };
};

}  // namespace kairos
