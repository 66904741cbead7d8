// Small hand-built systems for engine tests (independent of the initial-state module).
#pragma once

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "core/particle_system.hpp"
#include "model/environment.hpp"

namespace kairos::testing {

// N = n^D particles of diameter 1, mass 1 on a simple cubic/square lattice at packing fraction
// eta, random velocities with zero momentum and 2KE/(D(N-1)) = 1.
template <int D>
ParticleSystem<D> lattice_system(int n, double eta, std::uint64_t seed, double mass_ratio = 1.0,
                                 double diameter_ratio = 1.0) {
  ParticleSystem<D> s;
  int count = 1;
  for (int k = 0; k < D; ++k) count *= n;
  double vol = 0.0;
  for (int i = 0; i < count; ++i) {
    const double d = (i % 2 == 1) ? diameter_ratio : 1.0;
    vol += D == 3 ? M_PI * d * d * d / 6.0 : M_PI * d * d / 4.0;
  }
  const double L = std::pow(vol / eta, 1.0 / D);
  s.box.fill(L);
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Vec<D> p{};
  double msum = 0.0;
  for (int i = 0; i < count; ++i) {
    Kinematics<D> k{};
    int rem = i;
    for (int a = 0; a < D; ++a) {
      k.pos[a] = (rem % n + 0.25) * L / n;
      rem /= n;
      k.vel[a] = u(rng);
    }
    k.time = 0.0;
    k.radius = 0.5 * ((i % 2 == 1) ? diameter_ratio : 1.0);
    const double m = (i % 2 == 1) ? mass_ratio : 1.0;
    s.kinematics.push_back(k);
    s.mass.push_back(m);
    s.species.push_back(static_cast<std::uint32_t>(i % 2));
    p = p + m * k.vel;
    msum += m;
  }
  double ke = 0.0;
  for (int i = 0; i < count; ++i) {
    for (int a = 0; a < D; ++a) s.kinematics[i].vel[a] -= p[a] / msum;
    ke += 0.5 * s.mass[i] * norm2(s.kinematics[i].vel);
  }
  const double scale = std::sqrt(D * (count - 1) / (2.0 * ke));
  for (auto& k : s.kinematics) k.vel = scale * k.vel;
  s.species_names = {"A", "B"};
  return s;
}

// An engine and the one resumed from its exported state step together for `events` events:
// the same kinds at the same times, and then the same positions, velocities and spins, to the
// bit.
template <class Engine>
void expect_same_continuation(Engine& a, Engine& b, int events) {
  for (int k = 0; k < events; ++k) {
    ASSERT_EQ(a.step(), b.step()) << "event " << k;
    ASSERT_EQ(a.time(), b.time()) << "event " << k;
  }
  const auto x = a.export_state(), y = b.export_state();
  ASSERT_EQ(x.size(), y.size());
  for (std::size_t i = 0; i < x.size(); ++i) {
    ASSERT_EQ(x.kinematics[i].pos, y.kinematics[i].pos) << "particle " << i;
    ASSERT_EQ(x.kinematics[i].vel, y.kinematics[i].vel) << "particle " << i;
  }
  EXPECT_EQ(x.angular_velocity, y.angular_velocity);
}

// Walls on the faces of the last axis (the others periodic), every contact (particles and
// walls) of restitution e, under `gravity` along that axis: the set-up that walls with mass
// and containers are given their mass in.
template <int D>
Environment<D> walls_on_last_axis(double e = 1.0, double gravity = 0.0) {
  Environment<D> env;
  ContactModel law;
  law.normal = NormalRestitution::constant(e);
  if (e != 1.0) {
    env.species = 2;
    env.contact.assign(4, law);
  }
  env.gravity[D - 1] = gravity;
  for (int f = 2 * D - 2; f < 2 * D; ++f) {
    env.faces[f].kind = FaceKind::kWall;
    env.faces[f].wall.contact = law;
  }
  return env;
}

// The lattice gas moved half a spacing up each axis, so that no particle touches walls on the
// faces of the last axis (walls with mass, containers).
template <int D>
ParticleSystem<D> gas_between_walls(int n, double eta, std::uint64_t seed) {
  ParticleSystem<D> s = lattice_system<D>(n, eta, seed);
  for (Kinematics<D>& k : s.kinematics)
    for (int a = 0; a < D; ++a) k.pos[a] += 0.25 * s.box[a] / n;
  return s;
}

// A container under gravity -1 along the last axis: walls on the sides and a floor, an open
// top, every contact (pairs of `species` species and walls) of restitution e, the TC model's tc.
template <int D>
Environment<D> gravity_container(double e, double tc = 0.0, std::uint32_t species = 1) {
  Environment<D> env;
  env.gravity[D - 1] = -1.0;
  env.species = species;
  ContactModel law;
  law.normal = NormalRestitution::constant(e);
  env.contact.assign(static_cast<std::size_t>(species) * species, law);
  env.tc = tc;
  for (int f = 0; f < 2 * D - 1; ++f) {
    env.faces[f].kind = FaceKind::kWall;
    env.faces[f].wall.contact = law;
  }
  env.faces[2 * D - 1].kind = FaceKind::kOpen;
  return env;
}

}  // namespace kairos::testing
