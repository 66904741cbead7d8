// The string choices of the config (run.event_queue = "heap", contact.restitution_model = ...)
// as typed enums, one registry each (core/choices.hpp): name <-> enum <-> doc line. The reader
// accepts exactly the registered names (its error lists them), docs/config.md lists them, and
// the code that builds the run turns a name into its enum here instead of comparing strings.
// The choices of the potentials (kind, placement, shell_energy) are registered beside their
// factory, in interactions/potential_spec.hpp.
#pragma once

#include <string_view>

#include "core/choices.hpp"
#include "interactions/soft_contact.hpp"
#include "model/environment.hpp"

namespace kairos {

enum class Lattice { kFcc, kSc, kBcc, kHex, kSquare, kRandom };
enum class EventQueue { kCalendar, kHeap, kTree };
enum class IntegratorKind { kEvent, kDem };
enum class ProgressMode { kAuto, kAlways, kOff };  // auto, always, never
enum class IntervalUnit { kCollisions, kTime };
enum class TrajectoryPhases { kAll, kProduction };
enum class TrajectoryPrecision { kSingle, kDouble };
enum class TrajectorySpacing { kLinear, kLog };
enum class TrajectoryField {
  kPosition,
  kVelocity,
  kImage,
  kAngularVelocity,
  kTypeid,
  kDiameter,
  kMass
};
enum class DrivingKind { kNone, kAndersen, kWhiteNoise };
enum class RestitutionModel { kConstant, kViscoelastic, kTable };
// Box faces: 2k is the low face of axis k, 2k + 1 the high one (face_number()).
enum class BoxFace { kXLow, kXHigh, kYLow, kYHigh, kZLow, kZHigh };
enum class Axis { kX, kY, kZ };
// analysis.msd_time: the MSD's clock (auto: collisions for a freely cooling gas, else time).
enum class MsdTime { kAuto, kTime, kCollisions };
// system.size_distribution: per-particle diameters about each species' diameter.
enum class SizeDistribution { kNone, kUniform, kGaussian, kLognormal };

// system.lattice in a 3D or 2D box (dimension 2 or 3).
const Choices<Lattice>& lattices(int dimension);
const Choices<EventQueue>& event_queues();              // run.event_queue
const Choices<IntegratorKind>& integrators();           // run.integrator
const Choices<ProgressMode>& progress_modes();          // output.progress
const Choices<IntervalUnit>& interval_units();          // output.interval_unit
const Choices<DrivingKind>& driving_kinds();            // driving.kind
const Choices<RestitutionModel>& restitution_models();  // contact.restitution_model
const Choices<SoftModel>& soft_models();                // soft.model
const Choices<SoftCollisions>& soft_collision_modes();  // soft.collisions
// trajectory.gsd's options: output.trajectory_phases, trajectory_precision, trajectory_spacing
// and the names of output.trajectory_fields.
const Choices<TrajectoryPhases>& trajectory_phases();
const Choices<TrajectoryPrecision>& trajectory_precisions();
const Choices<TrajectorySpacing>& trajectory_spacings();
const Choices<TrajectoryField>& trajectory_fields();
const Choices<MsdTime>& msd_time_scales();              // analysis.msd_time
const Choices<SizeDistribution>& size_distributions();  // system.size_distribution
// boundary.wall[].face and boundary.open: the faces of a box of `dimension` (2 or 3), or all
// six (dimension 0).
const Choices<BoxFace>& box_faces(int dimension = 0);
// output.profile_axis ("" = none): the axes of a box of `dimension`.
const Choices<Axis>& axes(int dimension = 3);

constexpr int face_number(BoxFace face) {
  return static_cast<int>(face);
}
constexpr int face_axis(BoxFace face) {
  return face_number(face) / 2;
}

}  // namespace kairos
