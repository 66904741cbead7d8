// The check every boundary component's event times pass against dense sampling, and the
// energy budget of a silo test.
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

// A silo's energy budget, unit masses under g = 1 along the last axis: kinetic + rotational +
// potential energy, plus what collisions dissipated less the walls' work plus what the outlet
// took out: constant.
template <class Engine>
double silo_budget(const Engine& engine) {
  double e = engine.kinetic_energy() + engine.rotational_energy();
  for (const auto& p : engine.current_positions()) e += p[p.size() - 1];  // m g h
  const auto& c = engine.counters();
  return e + c.dissipated_in_collisions + c.dissipated_at_walls - c.work_by_walls + c.outlet_energy;
}

}  // namespace kairos::testing
