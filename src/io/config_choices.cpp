#include "io/config_choices.hpp"

#include <span>

namespace kairos {

namespace {

constexpr ChoiceEntry<Lattice> kLattices3D[] = {
    {"fcc", Lattice::kFcc, "face-centred cubic (the 3D default)"},
    {"sc", Lattice::kSc, "simple cubic"},
    {"bcc", Lattice::kBcc, "body-centred cubic"},
    {"random", Lattice::kRandom, "random sequential insertion"},
};
constexpr ChoiceEntry<Lattice> kLattices2D[] = {
    {"hex", Lattice::kHex, "hexagonal (the 2D default)"},
    {"square", Lattice::kSquare, "square"},
    {"random", Lattice::kRandom, "random sequential insertion"},
};
constexpr ChoiceEntry<EventQueue> kEventQueues[] = {
    {"calendar", EventQueue::kCalendar, "calendar queue"},
    {"heap", EventQueue::kHeap, "binary heap"},
    {"tree", EventQueue::kTree, "complete binary tournament tree"},
};
constexpr ChoiceEntry<IntegratorKind> kIntegrators[] = {
    {"event", IntegratorKind::kEvent, "the event-driven engine"},
    {"dem", IntegratorKind::kDem, "the force-based velocity Verlet integrator (needs [soft])"},
};
constexpr ChoiceEntry<ProgressMode> kProgressModes[] = {
    {"auto", ProgressMode::kAuto, "when stderr is a terminal"},
    {"always", ProgressMode::kAlways, "always"},
    {"never", ProgressMode::kOff, "never"},
};
constexpr ChoiceEntry<IntervalUnit> kIntervalUnits[] = {
    {"collisions", IntervalUnit::kCollisions, "collisions per particle"},
    {"time", IntervalUnit::kTime, "simulated time"},
};
constexpr ChoiceEntry<TrajectoryPhases> kTrajectoryPhases[] = {
    {"all", TrajectoryPhases::kAll, "frames from the start of the run, equilibration included"},
    {"production", TrajectoryPhases::kProduction, "frames from the start of the production"},
};
constexpr ChoiceEntry<TrajectoryPrecision> kTrajectoryPrecisions[] = {
    {"single", TrajectoryPrecision::kSingle, "float32, as HOOMD writes by default"},
    {"double", TrajectoryPrecision::kDouble, "float64 box, positions, velocities, sizes, masses"},
};
constexpr ChoiceEntry<TrajectorySpacing> kTrajectorySpacings[] = {
    {"linear", TrajectorySpacing::kLinear, "every trajectory_interval"},
    {"log", TrajectorySpacing::kLog,
     "at trajectory_interval x 10^(k / trajectory_frames_per_decade) from the phase's start"},
};
// HOOMD's names (particles/*), and Kairos's log/particles/angular_velocity.
constexpr ChoiceEntry<TrajectoryField> kTrajectoryFields[] = {
    {"position", TrajectoryField::kPosition, "particles/position (required)"},
    {"velocity", TrajectoryField::kVelocity, "particles/velocity"},
    {"image", TrajectoryField::kImage, "particles/image (the event integrator)"},
    {"angular_velocity", TrajectoryField::kAngularVelocity,
     "log/particles/angular_velocity (rough particles)"},
    {"typeid", TrajectoryField::kTypeid, "particles/typeid in every frame"},
    {"diameter", TrajectoryField::kDiameter, "particles/diameter in every frame"},
    {"mass", TrajectoryField::kMass, "particles/mass in every frame"},
};
constexpr ChoiceEntry<DrivingKind> kDrivingKinds[] = {
    {"none", DrivingKind::kNone, "no driving"},
    {"andersen", DrivingKind::kAndersen, "Andersen thermostat at `temperature`"},
    {"white_noise", DrivingKind::kWhiteNoise, "Gaussian velocity kicks of `strength`"},
};
constexpr ChoiceEntry<RestitutionModel> kRestitutionModels[] = {
    {"constant", RestitutionModel::kConstant, "e = restitution"},
    {"viscoelastic", RestitutionModel::kViscoelastic,
     "viscoelastic spheres: e(restitution_speed) = restitution"},
    {"table", RestitutionModel::kTable, "interpolated in restitution_table"},
};
constexpr ChoiceEntry<SoftModel> kSoftModels[] = {
    {"dashpot", SoftModel::LinearDashpot, "linear spring-dashpot"},
    {"hertz", SoftModel::ViscoelasticHertz, "viscoelastic Hertz"},
};
constexpr ChoiceEntry<SoftCollisions> kSoftCollisions[] = {
    {"mapped", SoftCollisions::kMapped, "the Mueller-Poeschel collision map"},
    {"instantaneous", SoftCollisions::kInstantaneous, "a hard-sphere collision with e(v_n)"},
};
constexpr ChoiceEntry<MsdTime> kMsdTimes[] = {
    {"auto", MsdTime::kAuto, "collisions for a freely cooling gas, time otherwise"},
    {"time", MsdTime::kTime, "simulated time"},
    {"collisions", MsdTime::kCollisions, "collisions per particle"},
};
constexpr ChoiceEntry<SizeDistribution> kSizeDistributions[] = {
    {"none", SizeDistribution::kNone, "every particle has its species' diameter"},
    {"uniform", SizeDistribution::kUniform, "uniform on [1 - sqrt(3) p, 1 + sqrt(3) p] d"},
    {"gaussian", SizeDistribution::kGaussian,
     "normal, mean d, standard deviation p d, cut to (0, 2d)"},
    {"lognormal", SizeDistribution::kLognormal,
     "log-normal with mean d and standard deviation p d"},
};
constexpr ChoiceEntry<BoxFace> kFaces[] = {
    {"x-", BoxFace::kXLow, "x = 0"},      {"x+", BoxFace::kXHigh, "x = L_x"},
    {"y-", BoxFace::kYLow, "y = 0"},      {"y+", BoxFace::kYHigh, "y = L_y"},
    {"z-", BoxFace::kZLow, "z = 0 (3D)"}, {"z+", BoxFace::kZHigh, "z = L_z (3D)"},
};
constexpr ChoiceEntry<Axis> kAxes[] = {
    {"x", Axis::kX, "x"},
    {"y", Axis::kY, "y"},
    {"z", Axis::kZ, "z (3D)"},
};

}  // namespace

const Choices<Lattice>& lattices(int dimension) {
  static constexpr Choices<Lattice> three("lattice", kLattices3D);
  static constexpr Choices<Lattice> two("lattice", kLattices2D);
  return dimension == 2 ? two : three;
}

const Choices<EventQueue>& event_queues() {
  static constexpr Choices<EventQueue> choices("event queue", kEventQueues);
  return choices;
}

const Choices<IntegratorKind>& integrators() {
  static constexpr Choices<IntegratorKind> choices("integrator", kIntegrators);
  return choices;
}

const Choices<ProgressMode>& progress_modes() {
  static constexpr Choices<ProgressMode> choices("progress mode", kProgressModes);
  return choices;
}

const Choices<IntervalUnit>& interval_units() {
  static constexpr Choices<IntervalUnit> choices("interval unit", kIntervalUnits);
  return choices;
}

const Choices<TrajectoryPhases>& trajectory_phases() {
  static constexpr Choices<TrajectoryPhases> choices("trajectory phases", kTrajectoryPhases);
  return choices;
}

const Choices<TrajectoryPrecision>& trajectory_precisions() {
  static constexpr Choices<TrajectoryPrecision> choices("trajectory precision",
                                                        kTrajectoryPrecisions);
  return choices;
}

const Choices<TrajectorySpacing>& trajectory_spacings() {
  static constexpr Choices<TrajectorySpacing> choices("trajectory spacing", kTrajectorySpacings);
  return choices;
}

const Choices<TrajectoryField>& trajectory_fields() {
  static constexpr Choices<TrajectoryField> choices("trajectory field", kTrajectoryFields);
  return choices;
}

const Choices<DrivingKind>& driving_kinds() {
  static constexpr Choices<DrivingKind> choices("driving kind", kDrivingKinds);
  return choices;
}

const Choices<RestitutionModel>& restitution_models() {
  static constexpr Choices<RestitutionModel> choices("restitution model", kRestitutionModels);
  return choices;
}

const Choices<SoftModel>& soft_models() {
  static constexpr Choices<SoftModel> choices("soft model", kSoftModels);
  return choices;
}

const Choices<SoftCollisions>& soft_collision_modes() {
  static constexpr Choices<SoftCollisions> choices("soft collision mode", kSoftCollisions);
  return choices;
}

const Choices<MsdTime>& msd_time_scales() {
  static constexpr Choices<MsdTime> choices("MSD time scale", kMsdTimes);
  return choices;
}

const Choices<SizeDistribution>& size_distributions() {
  static constexpr Choices<SizeDistribution> choices("size distribution", kSizeDistributions);
  return choices;
}

const Choices<BoxFace>& box_faces(int dimension) {
  static constexpr Choices<BoxFace> all("face", kFaces);
  static constexpr Choices<BoxFace> two("face", std::span(kFaces).first(4));
  return dimension == 2 ? two : all;
}

const Choices<Axis>& axes(int dimension) {
  static constexpr Choices<Axis> three("axis", kAxes);
  static constexpr Choices<Axis> two("axis", std::span(kAxes).first(2));
  return dimension == 2 ? two : three;
}

}  // namespace kairos
