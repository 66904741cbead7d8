// The check every boundary component's event times pass against dense sampling.
#pragma once

#include <gtest/gtest.h>

#include "dynamics/collision_time.hpp"

namespace kairos::testing {

// A predicted contact time against the first contact found by sampling in steps of h (kNever
// if none): never after the sampled contact, nor before the step it falls in; no contact
// predicted when none was sampled. Returns whether a contact was sampled (case k in messages).
inline bool agrees_with_sampling(double predicted, double sampled, double h, int k) {
  if (sampled == kNever) {
    EXPECT_EQ(predicted, kNever) << k;
    return false;
  }
  EXPECT_LE(predicted, sampled + 1e-12) << k;
  EXPECT_GT(predicted, sampled - h - 1e-12) << k;
  return true;
}

}  // namespace kairos::testing
