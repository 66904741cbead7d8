// From the run configuration to the engine's Environment: contact laws per species pair,
// walls, open faces and gravity (docs/config.md, sections [contact], [boundary], [field]).
#pragma once

#include <string>
#include <vector>

#include "core/particle_system.hpp"
#include "io/config.hpp"
#include "model/environment.hpp"

namespace kairos {

// The contact law a [contact]-style table describes. Throws InputError naming `where`.
ContactModel make_contact_model(const ContactConfig& c, const std::string& where);

// For the state `s`: its species names (index = species number) are what pair overrides and
// potentials name (a name the state does not have is an InputError); species missing from
// config.system.species get the default moment of inertia. Step tables ([[potential]],
// [[bond]]) are built for the contact distances of the state's particles: a species pair with
// a potential needs one contact distance (every particle of a species the same size), and so
// do the bonds of one type.
template <int D>
Environment<D> make_environment(const Config& config, const ParticleSystem<D>& s);

}  // namespace kairos
