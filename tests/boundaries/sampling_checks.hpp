// The check every boundary component's event times pass against dense sampling, and the
// grains and energy budget of a silo test.
#pragma once

#include <gtest/gtest.h>

#include <array>

#include "dynamics/collision_time.hpp"
#include "model/environment.hpp"

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

// A silo's environment before its floor and outlet: the box's `faces`, gravity -1 along the
// last axis, rough inelastic grains (restitution e, constant tangential restitution 0.4, the TC
// model at 1e-4) against each other and the faces. No sleeping, as in the silo examples: a
// draining silo with sleeping stops (the sleep rule holds grains on slopes steeper than
// friction would), and whether it stops within a test's events is a matter of the
// trajectory's last bits.
template <int D>
Environment<D> silo_grains(const std::array<Face<D>, 2 * D>& faces, double e) {
  Environment<D> env;
  env.gravity[D - 1] = -1.0;
  ContactModel law;
  law.normal = NormalRestitution::constant(e);
  law.tangential = TangentialModel::constant(0.4);
  env.species = 1;
  env.contact = {law};
  env.tc = 1e-4;
  env.sleep_speed = 0.0;
  env.faces = faces;
  for (Face<D>& f : env.faces) f.wall.contact = law;
  return env;
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
