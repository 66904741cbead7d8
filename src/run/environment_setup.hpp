// From the run configuration to the engine's Environment: contact laws per species pair,
// walls, open faces and gravity (docs/config.md, sections [contact], [boundary], [field]).
#pragma once

#include <string>
#include <vector>

#include "core/particle_system.hpp"
#include "io/config.hpp"
#include "io/config_models.hpp"
#include "model/environment.hpp"

namespace kairos {

// For the state `s`: its species names (index = species number) are what pair overrides and
// potentials name (a name the state does not have is an InputError); species missing from
// config.system.species get the default moment of inertia. Step tables ([[potential]],
// [[bond]]) are built for the contact distances of the state's particles: a species pair with
// a potential needs one contact distance (every particle of a species the same size), and so
// do the bonds of one type.
template <int D>
Environment<D> make_environment(const Config& config, const ParticleSystem<D>& s);

// Where the plane of the face wall `wc` lies at time t, less its face's rest position (0 or L):
// Wall::plane_position from the keys alone, for comparing two configurations before any
// Environment exists (a restart's, run/restart_plan.cpp).
double face_wall_offset(const WallConfig& wc, int dimension, double t);

}  // namespace kairos
