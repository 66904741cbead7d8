// From the run configuration to the engine's Environment: contact laws per species pair,
// walls, open faces and gravity (docs/config.md, sections [contact], [boundary], [field]).
#pragma once

#include <string>
#include <vector>

#include "core/environment.hpp"
#include "io/config.hpp"

namespace kairos {

// The contact law a [contact]-style table describes. Throws InputError naming `where`.
ContactModel make_contact_model(const ContactConfig& c, const std::string& where);

// `species_names` are the state's species (index = species number). Pair overrides name
// species; a name the state does not have is an InputError. Species missing from
// config.system.species get the default moment of inertia.
template <int D>
Environment<D> make_environment(const Config& config,
                                const std::vector<std::string>& species_names);

}  // namespace kairos
