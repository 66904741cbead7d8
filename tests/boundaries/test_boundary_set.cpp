// The boundary registry with two geometries: the face walls and the planes anywhere
// (boundaries/plane_walls, the example of docs/extending.md). Surfaces are numbered across
// components, each call reaches the component that owns the surface, and the soonest contact is
// found among all of them.
#include <gtest/gtest.h>

#include <cmath>

#include "model/boundaries.hpp"

namespace kairos {
namespace {

using Set = BoundarySet<3, FaceWalls<3>, PlaneWalls<3>>;

// The interface is the concept BoundaryComponent: every registered geometry meets it in both
// dimensions, and a type without the members does not (the registry would not compile with it).
static_assert(BoundaryComponent<FaceWalls<2>, 2> && BoundaryComponent<FaceWalls<3>, 3>);
static_assert(BoundaryComponent<PlaneWalls<2>, 2> && BoundaryComponent<PlaneWalls<3>, 3>);
static_assert(BoundaryComponent<CylinderWalls<2>, 2> && BoundaryComponent<CylinderWalls<3>, 3>);
static_assert(BoundaryComponent<SphereWalls<2>, 2> && BoundaryComponent<SphereWalls<3>, 3>);
// The face walls carry the walls with mass; the other geometries have no motion of their own.
static_assert(MovingBoundary<FaceWalls<2>, 2> && MovingBoundary<FaceWalls<3>, 3>);
static_assert(!MovingBoundary<PlaneWalls<3>, 3> && !MovingBoundary<CylinderWalls<3>, 3>);
struct OnlyAnAnyMember {
  bool any() const { return false; }
};
static_assert(!BoundaryComponent<OnlyAnAnyMember, 3>);

Set floor_and_a_slope() {
  std::array<Face<3>, 6> faces{};
  faces[4].kind = FaceKind::kWall;  // z-: the floor
  faces[5].kind = FaceKind::kWall;
  const Vec<3> gravity{0.0, 0.0, -1.0};
  // A slope x + z = 6 (normal into the domain: towards -x and -z), and its restitution 0.5.
  const double s = 1.0 / std::sqrt(2.0);
  PlaneWall<3> slope;
  slope.normal = {-s, 0.0, -s};
  slope.offset = -6.0 * s;
  slope.wall.contact.normal = NormalRestitution::constant(0.5);
  const Vec<3> box{10.0, 10.0, 10.0};
  return Set(FaceWalls<3>(faces, box, gravity), PlaneWalls<3>({slope}, box, faces, gravity));
}

TEST(BoundarySet, SurfacesAreNumberedAcrossComponents) {
  const Set set = floor_and_a_slope();
  EXPECT_TRUE(set.any());
  EXPECT_EQ(set.surfaces(), 7);  // six faces, then the slope
  EXPECT_TRUE(set.is_surface(6));
  EXPECT_FALSE(set.is_surface(0));
  const Vec<3> n = set.normal(6, {}, 0.0);
  EXPECT_NEAR(n[0], -1.0 / std::sqrt(2.0), 1e-15);
  // The centre (2, 5, 1) lies (6 - 3) / sqrt 2 from the slope.
  EXPECT_NEAR(set.gap(6, {2.0, 5.0, 1.0}, 0.0), 3.0 / std::sqrt(2.0), 1e-14);
  EXPECT_NEAR(set.gap(4, {2.0, 5.0, 1.0}, 0.0), 1.0, 1e-15);
  EXPECT_FALSE(set.any_surface_moves());
}

TEST(BoundarySet, TheSoonestContactIsFoundAmongAllComponents) {
  const Set set = floor_and_a_slope();
  const CellGrid<3> grid({10.0, 10.0, 10.0}, Vec<3>{1.0, 1.0, 1.0}, {true, true, false}, 1000);
  Set with_reach = set;
  with_reach.prepare(grid, 0.5, 0.0, true);
  // Moving along +x at 4, at height 3 (the floor 2.5 of free fall away, sqrt(5) = 2.24): the
  // slope comes first, where x + z = 6 - R sqrt 2 (its gap closes at 4 / sqrt 2, gravity
  // adding 1 / sqrt 2 per unit time).
  const Vec<3> x{1.0, 5.0, 3.0}, v{4.0, 0.0, 0.0};
  const auto [dt, surface] = with_reach.next_contact(x, v, 0.5, grid.locate(x), grid, 0.0, kNever);
  EXPECT_EQ(surface, 6);
  // x + z as a function of time: 4 + 4 t - t^2 / 2 = 6 - 0.5 sqrt 2.
  const double target = 6.0 - 0.5 * std::sqrt(2.0) - 4.0;
  const double expected = (4.0 - std::sqrt(16.0 - 2.0 * target)) / 1.0;
  EXPECT_NEAR(dt, expected, 1e-12);
  // Falling straight down in the floor's layer of cells, away from the slope: the floor. Higher
  // up, the floor is out of reach (the cell crossings come first) and the slope is never met.
  const Vec<3> y{0.5, 5.0, 0.9};
  const auto down =
      with_reach.next_contact(y, {0.0, 0.0, 0.0}, 0.5, grid.locate(y), grid, 0.0, kNever);
  EXPECT_EQ(down.second, 4);
  EXPECT_NEAR(down.first, std::sqrt(0.8), 1e-12);
  const Vec<3> high{0.5, 5.0, 3.0};
  EXPECT_EQ(with_reach.next_contact(high, {}, 0.5, grid.locate(high), grid, 0.0, kNever).second,
            -1);
}

TEST(BoundarySet, TheResponseComesFromTheSurfacesOwnLaw) {
  const Set set = floor_and_a_slope();
  const double s = 1.0 / std::sqrt(2.0);
  Vec<3> v{2.0, 1.0, 0.0};  // into the slope at 2 s along its normal
  Spin<3> w{};
  const ContactResult<3> r = set.resolve(6, Vec<3>{}, 0.0, 1.0, 0.5, 0.4, false, v, w);
  // Normal velocity -2s becomes +s (e = 0.5); the tangential part (1, 1, -1) s... unchanged.
  EXPECT_NEAR(dot(v, set.normal(6, {}, 0.0)), 0.5 * 2.0 * s, 1e-14);
  EXPECT_NEAR(v[1], 1.0, 1e-15);
  EXPECT_NEAR(r.dissipated, 0.5 * (2.0 * s * 2.0 * s) * (1.0 - 0.25), 1e-14);
  EXPECT_TRUE(set.overlaps({5.5, 5.0, 0.8}, 0.5, 0.0));  // the slope, not the floor
  EXPECT_FALSE(set.overlaps({2.0, 5.0, 1.0}, 0.5, 0.0));
  EXPECT_THROW(set.check_start({5.5, 5.0, 0.8}, 0.5, 0.0, 3), InputError);
}

}  // namespace
}  // namespace kairos
