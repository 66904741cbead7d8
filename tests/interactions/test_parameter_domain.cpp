// The physical domains of the contact laws' parameters (interactions/parameter_domain.hpp):
// their bounds at the edges, how messages say them, and that the factories and the config's key
// declarations read the same ones (a value one accepts the other accepts).
#include <gtest/gtest.h>

#include <limits>
#include <string>

#include "core/error.hpp"
#include "interactions/granular_contact.hpp"
#include "interactions/parameter_domain.hpp"
#include "interactions/soft_contact.hpp"
#include "io/config_keys.hpp"

namespace kairos {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kNan = std::numeric_limits<double>::quiet_NaN();

TEST(ParameterDomain, BoundsAtTheEdges) {
  EXPECT_TRUE(kRestitutionDomain.contains(0.0));
  EXPECT_TRUE(kRestitutionDomain.contains(1.0));
  EXPECT_FALSE(kRestitutionDomain.contains(1.0000000000000002));
  EXPECT_FALSE(kRestitutionDomain.contains(-1e-300));
  EXPECT_FALSE(kSoftRestitutionDomain.contains(0.0));  // open below
  EXPECT_TRUE(kSoftRestitutionDomain.contains(1e-300));
  EXPECT_FALSE(kPoissonRatioDomain.contains(-1.0));
  EXPECT_TRUE(kPoissonRatioDomain.contains(0.5));
  EXPECT_TRUE(kTangentialRestitutionDomain.contains(-1.0));
  for (const ParameterDomain& d : {kRestitutionDomain, kNonNegativeDomain, kPoissonRatioDomain}) {
    EXPECT_FALSE(d.contains(kNan));
    EXPECT_FALSE(d.contains(kInf));
    EXPECT_FALSE(d.contains(-kInf));
  }
}

TEST(ParameterDomain, MessagesSayTheDomain) {
  EXPECT_EQ(kRestitutionDomain.text(), "in [0, 1]");
  EXPECT_EQ(kPoissonRatioDomain.text(), "in (-1, 0.5]");
  EXPECT_EQ(kNonNegativeDomain.text(), "finite and >= 0");
  try {
    require_in(kSoftRestitutionDomain, 0.0, "e", "soft contact: ");
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), "soft contact: e must be in (0, 1], got 0");
  }
  EXPECT_THROW((void)NormalRestitution::constant(1.5), InputError);
  EXPECT_THROW((void)TangentialModel::constant(-1.5), InputError);
}

// The key declarations take their ranges from the domains: the same bounds, open or closed.
TEST(ParameterDomain, TheConfigDeclaresTheSameRanges) {
  const auto same = [](const char* key, const ParameterDomain& d) {
    const DeclaredKey* k = find_declared(key);
    ASSERT_NE(k, nullptr) << key;
    const Range& r = k->decl->range;
    EXPECT_EQ(r.lo, d.lo) << key;
    EXPECT_EQ(r.hi, d.hi) << key;
    EXPECT_EQ(r.lo_open, d.lo_open) << key;
    EXPECT_EQ(r.hi_open, d.hi_open) << key;
  };
  same("contact.restitution", kRestitutionDomain);
  same("contact.tangential_restitution", kTangentialRestitutionDomain);
  same("soft.poisson", kPoissonRatioDomain);
  same("soft.restitution", kSoftRestitutionDomain);
  same("soft.damping", kNonNegativeDomain);
  same("potential[0].restitution", kSoftRestitutionDomain);
  EXPECT_EQ(find_declared("contact.friction")->decl->range.lo, kNonNegativeDomain.lo);
}

}  // namespace
}  // namespace kairos
