// Shared checks of a soft sphere's contact with a moving wall (a face piston in
// test_soft_engine.cpp, a tilted plane in test_soft_planes.cpp).
#pragma once

#include <gtest/gtest.h>

#include "dem/dem_integrator.hpp"
#include "engine/event_engine.hpp"
#include "interactions/soft_contact.hpp"

namespace kairos::testing {

// Steps to the next soft release; after every event the budget kinetic + contact + dissipated
// at the walls - the walls' work stays what it was to 1e-12.
template <int D, class Queue>
void step_to_release_keeping_the_wall_budget(EventEngine<D, Queue>& engine) {
  const auto budget = [&] {
    const EventCounters& c = engine.counters();
    return engine.kinetic_energy() + engine.potential_energy() + c.dissipated_at_walls -
           c.work_by_walls;
  };
  const double e0 = budget();
  EventKind kind;
  while ((kind = engine.step()) != EventKind::kSoftRelease) {
    ASSERT_NE(kind, EventKind::kNone);
    EXPECT_NEAR(budget(), e0, 1e-12);
  }
  EXPECT_NEAR(budget(), e0, 1e-12);
}

// The DEM with the same laws and walls from the same start, at dt = t_c / 20 000 of the map's
// contact time, puts particle 0 where the event engine's state `after` (at engine_time) does
// 0.05 later, at its velocity, with the same work by the walls (to 1e-6).
template <int D>
void expect_the_dem_agrees(const ParticleSystem<D>& start, const Environment<D>& env,
                           const CollisionUnits& units, const CollisionMap& map, double engine_time,
                           const ParticleSystem<D>& after) {
  DemOptions options;
  options.dt = map.eps_t * units.time_unit / 20000.0;
  DemIntegrator<D> dem(start, env, options);
  dem.step(static_cast<long>((engine_time + 0.05) / options.dt));
  const Vec<D> x = after.position(0, dem.time());
  for (int a = 0; a < D; ++a) {
    EXPECT_NEAR(dem.position(0)[a], x[a], 1e-6) << a;
    EXPECT_NEAR(dem.velocity(0)[a], after.kinematics[0].vel[a], 1e-6) << a;
  }
  EXPECT_NEAR(dem.work_by_walls(), after.counters.work_by_walls, 1e-6);
}

}  // namespace kairos::testing
