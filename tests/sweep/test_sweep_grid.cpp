// The grid of a sweep (sweep/sweep_grid.hpp): the value forms, the order of the runs, their
// names, and the errors that name the bad argument.
#include "sweep/sweep_grid.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <set>
#include <string>

#include "core/error.hpp"

namespace kairos {
namespace {

using Values = std::vector<std::string>;

TEST(SweepGrid, EvenlySpacedValuesIncludeBothEnds) {
  const SweepAxis a = parse_sweep_axis("system.packing_fraction=0.1:0.5:9");
  EXPECT_EQ(a.key, "system.packing_fraction");
  EXPECT_EQ(a.values, (Values{"0.1", "0.15", "0.2", "0.25", "0.3", "0.35", "0.4", "0.45", "0.5"}));
  EXPECT_EQ(parse_sweep_axis("k=2:-1:4").values, (Values{"2", "1", "0", "-1"}));
  EXPECT_EQ(parse_sweep_axis("k=0.3:0.9:1").values, (Values{"0.3"}));
}

TEST(SweepGrid, LogSpacedValuesAreAGeometricSeries) {
  const SweepAxis a = parse_sweep_axis("contact.restitution=1e-3:1:4:log");
  ASSERT_EQ(a.values.size(), 4u);
  for (std::size_t i = 0; i < 4; ++i) {
    EXPECT_NEAR(std::stod(a.values[i]), std::pow(10.0, -3.0 + static_cast<double>(i)),
                1e-12 * std::pow(10.0, -3.0 + static_cast<double>(i)));
  }
  EXPECT_EQ(a.values.back(), "1");
}

TEST(SweepGrid, IntegerRangesAndListsAreTakenAsWritten) {
  EXPECT_EQ(parse_sweep_axis("system.seed=1..4").values, (Values{"1", "2", "3", "4"}));
  EXPECT_EQ(parse_sweep_axis("x=-2..0").values, (Values{"-2", "-1", "0"}));
  EXPECT_EQ(parse_sweep_axis("system.lattice=fcc, sc,bcc").values, (Values{"fcc", "sc", "bcc"}));
  // A TOML array or a quoted string holding commas is one value.
  EXPECT_EQ(parse_sweep_axis("g=[0, 0, -1],[0,-2,0]").values, (Values{"[0, 0, -1]", "[0,-2,0]"}));
  EXPECT_EQ(parse_sweep_axis("n=\"a,b\",c").values, (Values{"\"a,b\"", "c"}));
  EXPECT_EQ(parse_sweep_axis("t=0.5").values, (Values{"0.5"}));
}

TEST(SweepGrid, MalformedAxesAreRefusedNamingTheArgument) {
  for (const char* bad :
       {"system.seed", "=1..3", "k=", "k=1..", "k=3..1", "k=a..b", "k=1:2", "k=1:2:0", "k=1:2:x",
        "k=0:1:3:log", "k=1:2:3:lin", "k=nan:1:3", "k=1,,2", "k=1:2:3:4:5", "k=1..2000000",
        "k=0.1:0.1:5", "k=1,2,1", "k=0.1:0.1000000000001:2"}) {
    try {
      (void)parse_sweep_axis(bad);
      ADD_FAILURE() << bad << " was accepted";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(bad), std::string::npos) << e.what();
    }
  }
}

TEST(SweepGrid, TheFirstAxisVariesSlowest) {
  const std::vector<SweepAxis> axes = {parse_sweep_axis("system.packing_fraction=0.1,0.2"),
                                       parse_sweep_axis("system.seed=1..3")};
  const std::vector<SweepPoint> points = sweep_points(axes);
  ASSERT_EQ(points.size(), 6u);
  EXPECT_EQ(points[0].values, (Values{"0.1", "1"}));
  EXPECT_EQ(points[2].values, (Values{"0.1", "3"}));
  EXPECT_EQ(points[3].values, (Values{"0.2", "1"}));
  EXPECT_EQ(points[5].index, 5u);
  EXPECT_EQ(points[4].name, "0004_packing_fraction=0.2_seed=2");
  EXPECT_EQ(point_overrides(axes, points[4]),
            (Values{"system.packing_fraction=0.2", "system.seed=2"}));
}

TEST(SweepGrid, NamesAreUniqueAndSafeForAnyValue) {
  const std::vector<SweepAxis> axes = {
      parse_sweep_axis("system.species.0.diameter=1,2"),
      parse_sweep_axis("system.species.1.diameter=1,2"),
      parse_sweep_axis("gravity.vector=[0, 0, -1],[0,0,-1.0000000000000000000000000000001]")};
  const std::vector<SweepPoint> points = sweep_points(axes);
  std::set<std::string> names;
  for (const SweepPoint& p : points) {
    EXPECT_EQ(p.name.find_first_not_of(
                  "abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789._+=-"),
              std::string::npos)
        << p.name;
    EXPECT_LT(p.name.size(), 200u);
    names.insert(p.name);
  }
  EXPECT_EQ(names.size(), points.size());
  // Two keys that end alike are named in full.
  EXPECT_EQ(points[0].name.rfind("0000_system.species.0.diameter=1_system.species.1.diameter=1", 0),
            0u)
      << points[0].name;
}

TEST(SweepGrid, GridsThatCannotBeRunAreRefused) {
  EXPECT_THROW((void)sweep_points({}), InputError);
  EXPECT_THROW(
      (void)sweep_points({parse_sweep_axis("system.seed=1..3"), parse_sweep_axis("system.seed=4")}),
      InputError);
  EXPECT_THROW((void)sweep_points({parse_sweep_axis("a=1..1000"), parse_sweep_axis("b=1..1000"),
                                   parse_sweep_axis("c=1..2")}),
               InputError);
}

}  // namespace
}  // namespace kairos
