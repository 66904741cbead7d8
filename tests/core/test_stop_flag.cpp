// The stop flag (src/core/stop_flag.hpp): a requested stop, or a setup deadline that has passed,
// ends every long setup computation with kairos::Interrupted (soft-sphere map tables, the
// collision-map integrator at setup, solving for a restitution, step tables and their
// quadratures, random insertion), and nothing else changes: the same computations without a
// stop give the same results as before.
#include "core/stop_flag.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <optional>
#include <random>
#include <thread>

#include "core/error.hpp"
#include "init/initial_state.hpp"
#include "interactions/potential_spec.hpp"
#include "interactions/soft_contact.hpp"
#include "interactions/soft_map_table.hpp"
#include "io/config.hpp"

namespace kairos {
namespace {

// Each test starts and ends without a stop request.
class StopFlag : public ::testing::Test {
 protected:
  void SetUp() override { clear_stop_request(); }
  void TearDown() override { clear_stop_request(); }
};

// The cause of the Interrupted that f throws, or nothing thrown.
template <class F>
std::optional<Interrupted::Cause> interruption_of(F&& f) {
  try {
    f();
  } catch (const Interrupted& e) {
    return e.cause();
  }
  return std::nullopt;
}

SoftTableSpec small_table() {
  SoftTableSpec s;
  s.law = SoftContactLaw::viscoelastic_hertz(1e5, 1e-3);
  s.min_normal_speed = 1.0;
  s.max_normal_speed = 2.0;
  s.max_tangential_ratio = 1.0;
  s.tolerance = 1e-4;
  return s;
}

PotentialSpec lennard_jones_volume_rule() {
  PotentialSpec p;
  p.kind = "lennard_jones";
  p.steps = 50;
  return p;
}

TEST_F(StopFlag, RequestAndClear) {
  EXPECT_FALSE(stop_requested());
  EXPECT_NO_THROW(throw_if_stop_requested());
  request_stop();
  EXPECT_TRUE(stop_requested());
  EXPECT_EQ(interruption_of([] { throw_if_stop_requested(); }), Interrupted::Cause::kStopRequest);
  clear_stop_request();
  EXPECT_FALSE(stop_requested());
}

TEST_F(StopFlag, InterruptedIsNoInputError) {
  // Handlers that add context to an InputError (environment setup, potential specs) must let
  // an interruption through unchanged.
  request_stop();
  try {
    throw_if_stop_requested();
    FAIL() << "no exception";
  } catch (const InputError&) {
    FAIL() << "Interrupted must not be an InputError";
  } catch (const Interrupted&) {
  }
}

TEST_F(StopFlag, DeadlineOnlyWhileInScope) {
  {
    const ScopedStopDeadline deadline(0.02);
    EXPECT_NO_THROW(throw_if_stop_requested());
    std::this_thread::sleep_for(std::chrono::milliseconds(40));
    EXPECT_EQ(interruption_of([] { throw_if_stop_requested(); }), Interrupted::Cause::kWallTime);
    {
      const ScopedStopDeadline none(0.0);  // no limit of its own: the outer one holds
      EXPECT_TRUE(interruption_of([] { throw_if_stop_requested(); }).has_value());
    }
  }
  EXPECT_NO_THROW(throw_if_stop_requested());
  const ScopedStopDeadline far(3600.0);
  EXPECT_NO_THROW(throw_if_stop_requested());
}

TEST_F(StopFlag, StopsSoftMapTableBuilds) {
  request_stop();
  EXPECT_EQ(interruption_of([] { SoftMapTable::build(small_table()); }),
            Interrupted::Cause::kStopRequest);
  clear_stop_request();
  EXPECT_NO_THROW(SoftMapTable::build(small_table()));
}

TEST_F(StopFlag, StopsTheCollisionMapOnlyWhenInterruptible) {
  ReducedCollision r;
  r.model = SoftModel::ViscoelasticHertz;
  r.l_tilde = 1e3;
  r.c_dis = 0.1;
  const CollisionMap reference = collision_map(r);
  request_stop();
  const CollisionMap engine = collision_map(r);  // the engine's default: never abandoned
  EXPECT_EQ(engine.eps_rdot, reference.eps_rdot);
  MapOptions setup;
  setup.interruptible = true;
  EXPECT_EQ(interruption_of([&] { collision_map(r, setup); }), Interrupted::Cause::kStopRequest);
}

TEST_F(StopFlag, StopsSolvingForARestitution) {
  request_stop();
  EXPECT_TRUE(interruption_of([] {
                viscoelastic_dissipation_for_restitution(0.5, 1e5, 0.3, 1.0);
              }).has_value());
}

TEST_F(StopFlag, StopsStepTablesAndTheirQuadratures) {
  const StepTable reference = make_step_table(lennard_jones_volume_rule(), 0.9);
  request_stop();
  EXPECT_TRUE(
      interruption_of([] { make_step_table(lennard_jones_volume_rule(), 0.9); }).has_value());
  EXPECT_TRUE(interruption_of([] {
                second_virial(continuous_potential(lennard_jones_volume_rule()), 0.9, 1.0);
              }).has_value());
  clear_stop_request();
  const StepTable again = make_step_table(lennard_jones_volume_rule(), 0.9);
  EXPECT_EQ(again.boundary, reference.boundary);
  EXPECT_EQ(again.energy, reference.energy);
}

TEST_F(StopFlag, StopsRandomInsertion) {
  SystemConfig s;
  s.particles = 5000;
  s.packing_fraction = 0.3;
  s.lattice = "random";
  s.species.emplace_back();
  std::mt19937_64 rng(1);
  request_stop();
  EXPECT_TRUE(interruption_of([&] { make_initial_state<3>(s, rng); }).has_value());
}

}  // namespace
}  // namespace kairos
