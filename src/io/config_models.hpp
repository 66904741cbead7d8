// The model's parts that a config's keys describe: a contact law, a wall's motion, a plane
// through a point. Shared by the set-up of the Environment (run/environment_setup.hpp) and the
// boundary tables (io/tables/).
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "boundaries/face_wall.hpp"
#include "core/vec.hpp"
#include "interactions/granular_contact.hpp"
#include "io/wall_config.hpp"

namespace kairos {

// The contact law a [contact]-style table describes. Throws InputError naming `where`.
ContactModel make_contact_model(const ContactConfig& c, const std::string& where);

// A vector key (the reader made sure it has D components, or none: then zero).
template <int D>
Vec<D> to_vec(const std::vector<double>& v);

// The plane through `point` with the given normal (not 0: the reader), as (unit normal, offset)
// of n . x = offset: a plane wall's or an outlet's.
template <int D>
std::pair<Vec<D>, double> plane_through(const std::vector<double>& normal,
                                        const std::vector<double>& point);

// A wall's motion from its keys (velocity, vibration, mass and force), without its contact law.
template <int D>
Wall<D> wall_motion(const WallConfig& wc);

// A wall's contact law and motion from its keys (a face wall's or a plane's).
template <int D>
Wall<D> make_wall(const WallConfig& wc, const std::string& where);

}  // namespace kairos
