// The one list of a run's outputs and analyses (HOOMD's operations list): the run driver calls
// them in this order at every moment of the run (outputs/observer.hpp). A new output is one
// file pair in src/run/outputs/, one line in make_observers and its type in AllOutputs
// (registry.cpp; docs/extending.md).
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "io/config.hpp"
#include "run/compression.hpp"
#include "run/integrator.hpp"
#include "run/outputs/observer.hpp"

namespace kairos {

template <int D>
using ObserverList = std::vector<std::unique_ptr<Observer<D>>>;

// What a new run's setup did that its outputs report: its compression, and the packing it left.
template <int D>
struct SetupOutcome {
  std::shared_ptr<const CompressionReport> compression;  // null: none
  std::shared_ptr<const ParticleSystem<D>> packing;
};

// The observers of a run of `config` by `integrator` (which they read; it outlives them).
template <int D>
ObserverList<D> make_observers(const Config& config, const Integrator<D>& integrator,
                               const SetupOutcome<D>& setup = {});

// Every file an output or analysis of make_observers may write into the output directory,
// whatever the configuration (an earlier run's may have had others): the files the
// directory's guard refuses to clobber and --overwrite removes (run/output_directory.cpp). Each
// output declares its files once, as its kFiles; this is their union, with run.log.
const std::vector<std::string>& output_file_names();

}  // namespace kairos
