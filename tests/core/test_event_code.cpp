// The typed event code (core/event_code.hpp): the 32 bits restart files store (EventSlot::
// partner), the kinds they name, which stored bits make sense for n particles, and renumbering.
#include <gtest/gtest.h>

#include <cstdint>
#include <random>
#include <vector>

#include "core/event_code.hpp"

namespace kairos {
namespace {

TEST(EventCode, BitsAreTheStoredFormat) {
  using Code = EventCode<3>;
  EXPECT_EQ(Code::collision(5).bits(), 5u);
  EXPECT_EQ(Code::crossing().bits(), 0xffffffffu);
  EXPECT_EQ(Code::wall(0).bits(), 0xffffffffu - 6u);
  EXPECT_EQ(Code::wall(5).bits(), 0xffffffffu - 1u);
  EXPECT_EQ(Code::release().bits(), 0xffffffffu - 7u);
  EXPECT_EQ(Code::crossing_keeping_none().bits(), 0xffffffffu - 8u);
  EXPECT_EQ(Code::crossing_keeping(3).bits(), 0x80000003u);
  EXPECT_EQ(EventCode<2>::wall(3).bits(), 0xffffffffu - 1u);
  EXPECT_EQ(EventCode<2>::release().bits(), 0xffffffffu - 5u);
}

TEST(EventCode, PredicatesNameEachKindOnce) {
  using Code = EventCode<3>;
  const Code codes[] = {Code::collision(7),
                        Code::crossing(),
                        Code::crossing_keeping(7),
                        Code::crossing_keeping_none(),
                        Code::wall(2),
                        Code::release()};
  for (const Code c : codes) {
    const int kinds = c.is_collision() + c.is_crossing() + c.is_wall() + c.is_release();
    EXPECT_EQ(kinds, 1) << c.bits();
  }
  EXPECT_TRUE(Code::crossing_keeping(7).keeps_contact());
  EXPECT_EQ(Code::crossing_keeping(7).kept_partner(), 7u);
  EXPECT_TRUE(Code::crossing_keeping_none().keeps_nothing());
  EXPECT_TRUE(Code::crossing().is_full_scan_crossing());
  EXPECT_EQ(Code::wall(4).wall_face(), 4);
  EXPECT_EQ(Code::from_bits(Code::wall(4).bits()), Code::wall(4));
}

TEST(EventCode, RenumberingMovesParticlesOnly) {
  using Code = EventCode<3>;
  const auto plus_ten = [](std::uint32_t p) { return p + 10; };
  EXPECT_EQ(Code::collision(1).renumbered(plus_ten), Code::collision(11));
  EXPECT_EQ(Code::crossing_keeping(1).renumbered(plus_ten), Code::crossing_keeping(11));
  EXPECT_EQ(Code::wall(1).renumbered(plus_ten), Code::wall(1));
  EXPECT_EQ(Code::release().renumbered(plus_ten), Code::release());
  EXPECT_TRUE(Code::valid_bits(Code::collision(9).bits(), 10));
  EXPECT_FALSE(Code::valid_bits(Code::collision(10).bits(), 10));
  EXPECT_FALSE(Code::valid_bits(Code::crossing_keeping(10).bits(), 10));
  EXPECT_TRUE(Code::valid_bits(Code::wall(3).bits(), 10));
}

// The layout of the header's table, written out independently of the class: what stored bits
// mean in dimension D.
enum class Kind { kCollision, kKept, kNoneKept, kRelease, kWall, kFullScan };

template <int D>
Kind kind_by_the_table(std::uint32_t bits) {
  const std::uint32_t all = 0xffffffffu;
  if (bits < 0x80000000u) return Kind::kCollision;
  if (bits == all) return Kind::kFullScan;
  if (bits >= all - 2 * D) return Kind::kWall;
  if (bits == all - 2 * D - 1) return Kind::kRelease;
  if (bits == all - 2 * D - 2) return Kind::kNoneKept;
  // The surfaces after the box faces: the 4096 - 2D codes just below kNoneKept.
  if (bits >= all - 2 * D - 2 - (4096 - 2 * D)) return Kind::kWall;
  return Kind::kKept;
}

// The surface a wall code names: a face (from the top), or a surface after the faces.
template <int D>
int surface_by_the_table(std::uint32_t bits) {
  const std::uint32_t all = 0xffffffffu;
  if (bits >= all - 2 * D) return static_cast<int>(bits - (all - 2 * D));
  return 2 * D + static_cast<int>(bits - (all - 2 * D - 2 - (4096 - 2 * D)));
}

template <int D>
void every_bit_pattern_names_one_kind() {
  using Code = EventCode<D>;
  const std::uint32_t all = 0xffffffffu, base = 0x80000000u;
  // Both sides of every edge of the table, and random patterns.
  std::vector<std::uint32_t> bits = {0u, 1u, base - 2, base - 1, base, base + 1};
  for (std::uint32_t k = 0; k <= 2 * D + 4; ++k) bits.push_back(all - k);
  const std::uint32_t first_surface = all - 2 * D - 2 - (4096 - 2 * D);
  for (const std::uint32_t b :
       {first_surface - 2, first_surface - 1, first_surface, first_surface + 1})
    bits.push_back(b);
  std::mt19937 rng(11);
  for (int k = 0; k < 20000; ++k) bits.push_back(static_cast<std::uint32_t>(rng()));
  for (const std::uint32_t b : bits) {
    const Code c = Code::from_bits(b);
    const Kind want = kind_by_the_table<D>(b);
    ASSERT_EQ(c.bits(), b);
    const int kinds = c.is_collision() + c.is_crossing() + c.is_wall() + c.is_release();
    ASSERT_EQ(kinds, 1) << b;
    EXPECT_EQ(c.is_collision(), want == Kind::kCollision) << b;
    EXPECT_EQ(c.is_wall(), want == Kind::kWall) << b;
    EXPECT_EQ(c.is_release(), want == Kind::kRelease) << b;
    // A crossing is exactly one of: keeps a contact, keeps nothing, scans everything.
    EXPECT_EQ(c.keeps_contact(), want == Kind::kKept) << b;
    EXPECT_EQ(c.keeps_nothing(), want == Kind::kNoneKept) << b;
    EXPECT_EQ(c.is_full_scan_crossing(), want == Kind::kFullScan) << b;
    EXPECT_EQ(c.is_crossing(),
              c.keeps_contact() + c.keeps_nothing() + c.is_full_scan_crossing() == 1)
        << b;
    if (want == Kind::kCollision) {
      EXPECT_EQ(c, Code::collision(b));
    }
    if (want == Kind::kKept) {
      EXPECT_EQ(c, Code::crossing_keeping(b - base));
    }
    if (want == Kind::kWall) {
      EXPECT_EQ(c.wall_face(), surface_by_the_table<D>(b));
      EXPECT_EQ(c, Code::wall(c.wall_face()));
    }
  }
  // The faces: one code per face of the box, the last just below kNoPartner.
  for (int f = 0; f < 2 * D; ++f) {
    EXPECT_TRUE(Code::wall(f).is_wall()) << f;
    EXPECT_EQ(Code::wall(f).wall_face(), f);
  }
  EXPECT_EQ(Code::wall(2 * D - 1).bits(), all - 1);
  // An empty slot (the default) is a crossing that scans every neighbour cell.
  EXPECT_EQ(Code{}, Code::crossing());
  EXPECT_TRUE(PendingEvent<D>{}.code.is_full_scan_crossing());
}

TEST(EventCode, EveryBitPatternNamesTheKindOfTheStoredTable) {
  every_bit_pattern_names_one_kind<2>();
  every_bit_pattern_names_one_kind<3>();
}

template <int D>
void valid_bits_at_the_edges() {
  using Code = EventCode<D>;
  const std::uint32_t n = 10;
  // Collisions: the partner must be a particle.
  EXPECT_TRUE(Code::valid_bits(Code::collision(0).bits(), n));
  EXPECT_TRUE(Code::valid_bits(Code::collision(n - 1).bits(), n));
  EXPECT_FALSE(Code::valid_bits(Code::collision(n).bits(), n));
  EXPECT_FALSE(Code::valid_bits(Code::kKeptBase - 1, n));  // the last collision code
  EXPECT_TRUE(Code::valid_bits(Code::kKeptBase - 1, Code::kKeptBase));
  EXPECT_FALSE(Code::valid_bits(Code::collision(0).bits(), 0));  // no particles, no partner
  // Kept contacts: the kept partner must be a particle.
  EXPECT_TRUE(Code::valid_bits(Code::crossing_keeping(0).bits(), n));
  EXPECT_TRUE(Code::valid_bits(Code::crossing_keeping(n - 1).bits(), n));
  EXPECT_FALSE(Code::valid_bits(Code::crossing_keeping(n).bits(), n));
  EXPECT_FALSE(Code::valid_bits(Code::kFirstSurface - 1, n));  // the last kept code
  EXPECT_TRUE(Code::valid_bits(Code::kFirstSurface, n));       // the first surface after the faces
  EXPECT_FALSE(Code::valid_bits(Code::crossing_keeping(0).bits(), 0));
  // Codes that name no particle make sense for any n, none included.
  for (const std::uint32_t m : {0u, 1u, n}) {
    EXPECT_TRUE(Code::valid_bits(Code::crossing_keeping_none().bits(), m));
    EXPECT_TRUE(Code::valid_bits(Code::release().bits(), m));
    EXPECT_TRUE(Code::valid_bits(Code::crossing().bits(), m));
    for (int f = 0; f < 2 * D; ++f) EXPECT_TRUE(Code::valid_bits(Code::wall(f).bits(), m));
  }
}

TEST(EventCode, ValidBitsAtTheEdgesOfEachRange) {
  valid_bits_at_the_edges<2>();
  valid_bits_at_the_edges<3>();
}

// The engine takes at most kMaxParticles particles (EventEngine's constructor): every index it
// can hand out fits the kept range, below the codes that name no particle.
template <int D>
void kept_range_holds_every_engine_index() {
  using Code = EventCode<D>;
  const std::uint32_t most = Code::kMaxParticles;  // the engine's largest particle count
  const std::uint32_t last = most - 1;
  EXPECT_LE(last, Code::kFirstSurface - Code::kKeptBase - 1);
  EXPECT_EQ(most, (1u << 31) - 4099u);  // below kNoPartner, release, none-kept, 4096 surfaces
  const Code kept = Code::crossing_keeping(last);
  EXPECT_FALSE(kept.is_wall());
  EXPECT_TRUE(kept.keeps_contact());
  EXPECT_FALSE(kept.keeps_nothing());
  EXPECT_EQ(kept.kept_partner(), last);
  EXPECT_EQ(Code::from_bits(kept.bits()), kept);
  EXPECT_TRUE(Code::valid_bits(kept.bits(), most));
  EXPECT_TRUE(Code::collision(last).is_collision());
  EXPECT_TRUE(Code::valid_bits(Code::collision(last).bits(), most));
}

TEST(EventCode, TheKeptRangeHoldsEveryIndexTheEngineHandsOut) {
  kept_range_holds_every_engine_index<2>();
  kept_range_holds_every_engine_index<3>();
}

TEST(EventCode, RenumberingThroughAPermutationAndBack) {
  using Code = EventCode<3>;
  const std::vector<std::uint32_t> new_index{3, 0, 4, 1, 2};  // new_index[old] = new
  std::vector<std::uint32_t> old_index(new_index.size());
  for (std::uint32_t k = 0; k < new_index.size(); ++k) old_index[new_index[k]] = k;
  int calls = 0;
  const auto forward = [&](std::uint32_t p) {
    ++calls;
    return new_index[p];
  };
  const auto back = [&](std::uint32_t p) { return old_index[p]; };
  for (std::uint32_t p = 0; p < new_index.size(); ++p) {
    EXPECT_EQ(Code::collision(p).renumbered(forward), Code::collision(new_index[p]));
    EXPECT_EQ(Code::crossing_keeping(p).renumbered(forward), Code::crossing_keeping(new_index[p]));
    EXPECT_EQ(Code::collision(p).renumbered(forward).renumbered(back), Code::collision(p));
    EXPECT_EQ(Code::crossing_keeping(p).renumbered(forward).renumbered(back),
              Code::crossing_keeping(p));
  }
  EXPECT_EQ(calls, 4 * static_cast<int>(new_index.size()));
  // Codes without a particle never ask for a new number (the map need not even cover them).
  calls = 0;
  const Code none[] = {Code::crossing(), Code::crossing_keeping_none(), Code::release(),
                       Code::wall(0), Code::wall(5)};
  for (const Code c : none) EXPECT_EQ(c.renumbered(forward), c);
  EXPECT_EQ(calls, 0);
}

}  // namespace
}  // namespace kairos
