// Ranges of the config's dimensional keys, checked against the scales of the state a run
// starts from (docs/config.md lists every range).
//
// The parser (io/config.cpp) checks what needs no scale: types, signs, dimensionless ranges
// (restitutions, Poisson's ratio, fractions), counts. A stiffness, a speed, a time or a length
// has a meaningful range only in the units the user chose: here those units are the smallest and
// largest diameter d_min, d_max, the smallest mass m, kT = system.temperature, the thermal speed
// v = sqrt(kT / m) and the time tau = d_min / v of the start state (read from the restart or
// initial_state file when there is one), and the box. Outside these ranges the numerics break
// down (a quadrature over a cut-off of 1e300, kicks 1e-300 apart, a clock that can no longer
// advance, energies that overflow) or the run could never be afforded; the ranges are wide,
// about 1e-9 to 1e9 in these units where nothing tighter follows, so no real use is refused.
// Every error names the key, its value and the allowed range in the key's own units.
#pragma once

#include <string>
#include <vector>

#include "core/particle_system.hpp"
#include "interactions/potential_spec.hpp"
#include "io/config.hpp"
#include "io/range_checks.hpp"

namespace kairos {

// The scales of a start state, or of the config alone (its species; no box).
template <int D>
RangeScales range_scales(const Config& config, const ParticleSystem<D>& state);
RangeScales range_scales(const Config& config);

// Throws InputError naming the first key out of range.
void check_ranges(const Config& config, const RangeScales& scales);
// The keys of one [[potential]] / [[bond]] entry (prefix "potential[0]"), for cores up to
// scales.d_max; kairos steps calls it alone.
void check_potential_ranges(const PotentialSpec& spec, const std::string& prefix,
                            const RangeScales& scales);

}  // namespace kairos
