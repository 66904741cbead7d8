#include "run/outputs/registry.hpp"

#include <algorithm>
#include <stdexcept>
#include <utility>

#include "run/dem_adapter.hpp"
#include "run/event_adapter.hpp"
#include "run/outputs/bond_order_output.hpp"
#include "run/outputs/compression_output.hpp"
#include "run/outputs/dem_summary.hpp"
#include "run/outputs/event_summary.hpp"
#include "run/outputs/granular_summary.hpp"
#include "run/outputs/msd_output.hpp"
#include "run/outputs/pressure_tensor.hpp"
#include "run/outputs/profile_output.hpp"
#include "run/outputs/rdf_output.hpp"
#include "run/outputs/restart_output.hpp"
#include "run/outputs/run_summary.hpp"
#include "run/outputs/soft_summary.hpp"
#include "run/outputs/stepped_summary.hpp"
#include "run/outputs/structure_factor_output.hpp"
#include "run/outputs/structure_snapshot.hpp"
#include "run/outputs/thermo_output.hpp"
#include "run/outputs/trajectory_output.hpp"
#include "run/outputs/transport_output.hpp"
#include "run/outputs/velocity_distribution_output.hpp"
#include "run/outputs/walls_with_mass_summary.hpp"
#include "run/run_log.hpp"

namespace kairos {

namespace {

template <class T, int D, class... Args>
T& add(ObserverList<D>& list, Args&&... args) {
  auto observer = std::make_unique<T>(std::forward<Args>(args)...);
  T& added = *observer;
  list.push_back(std::move(observer));
  return added;
}

// Every output and analysis make_observers may create: the files they declare (their kFiles)
// are output_file_names(). A new output is added here and in make_observers; make_observers
// refuses one whose files this list misses (require_files_listed), so a run of it fails its tests.
template <class... Outputs>
struct OutputKinds {
  static std::vector<std::string> files() {
    std::vector<std::string> names;
    (names.insert(names.end(), Outputs::kFiles.begin(), Outputs::kFiles.end()), ...);
    return names;
  }
};
using AllOutputs = OutputKinds<RunSummary<3>, ThermoOutput<3>, TrajectoryOutput<3>,
                               RestartOutput<3>, ProfileOutput<3>, TransportOutput<3>, MsdOutput<3>,
                               RdfOutput<3>, StructureFactorOutput<3>, BondOrderOutput<3>,
                               VelocityDistributionOutput<3>, CompressionOutput<3>>;

template <int D>
void require_files_listed(const ObserverList<D>& list) {
  const auto& listed = output_file_names();
  const auto require = [&](const std::string& file) {
    if (std::find(listed.begin(), listed.end(), file) == listed.end()) {
      throw std::logic_error("output file '" + file +
                             "' is not in output_file_names(): add its output to AllOutputs "
                             "(run/outputs/registry.cpp)");
    }
  };
  for (const auto& observer : list) {
    if (observer->writes_file()) require(observer->name());
    for (const std::string& more : observer->more_files()) require(more);
  }
}

}  // namespace

// `config`: for an output registered only under some configuration (every one here decides for
// itself at open(), so that summary.json lists a file an earlier run left).
template <int D>
ObserverList<D> make_observers(const Config& config, const Integrator<D>& integrator,
                               const SetupOutcome<D>& setup) {
  ObserverList<D> list;
  if (setup.compression) add<CompressionOutput<D>>(list, setup.compression, setup.packing);
  // The order matters where one output records another: the row and the frame due at one
  // moment come before the restart file that records them, and every file before summary.json.
  const ThermoOutput<D>& thermo = add<ThermoOutput<D>>(list);
  add<TrajectoryOutput<D>>(list);
  add<RestartOutput<D>>(list);
  add<ProfileOutput<D>>(list);
  // Analyses that write their own file (before summary.json, which lists it).
  // The transport part of summary.json before the MSD's, whose finite-size correction uses the
  // shear viscosity measured in the same run.
  if (const EventIntegrator<D>* engine = integrator.as_event(); engine && config.analysis.transport)
    add<TransportOutput<D>>(list, config, *engine);
  if (const EventIntegrator<D>* engine = integrator.as_event(); engine && config.analysis.msd)
    add<MsdOutput<D>>(list, config, *engine);
  // The structure analyses of [analysis]: the three of the configuration share one read of the
  // state per sample; rdf.tsv's part of summary.json reads thermo.tsv's Z.
  const auto snapshot = std::make_shared<StructureSnapshot<D>>();
  add<RdfOutput<D>>(list, snapshot, thermo);
  add<StructureFactorOutput<D>>(list, snapshot);
  add<BondOrderOutput<D>>(list, snapshot);
  add<VelocityDistributionOutput<D>>(list);
  // summary.json's parts.
  add<RunSummary<D>>(list);
  if (const EventIntegrator<D>* engine = integrator.as_event()) {
    add<EventSummary<D>>(list, *engine);
    add<PressureTensor<D>>(list, *engine, thermo);
    if (engine->stepped()) add<SteppedSummary<D>>(list, *engine, thermo);
    if (engine->soft()) add<SoftSummary<D>>(list, *engine);
    if (engine->kind().granular) add<GranularSummary<D>>(list, *engine);
  }
  if (const DemAdapter<D>* dem = integrator.as_dem()) add<DemSummary<D>>(list, *dem);
  if (!integrator.walls_with_mass().empty()) add<WallsWithMassSummary<D>>(list, thermo);
  require_files_listed(list);
  return list;
}

const std::vector<std::string>& output_file_names() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> all = AllOutputs::files();
    all.emplace_back(RunLog::kFile);
    return all;
  }();
  return names;
}

template ObserverList<2> make_observers<2>(const Config&, const Integrator<2>&,
                                           const SetupOutcome<2>&);
template ObserverList<3> make_observers<3>(const Config&, const Integrator<3>&,
                                           const SetupOutcome<3>&);

}  // namespace kairos
