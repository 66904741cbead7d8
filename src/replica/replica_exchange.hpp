// Replica exchange in temperature (`kairos replica-exchange`, docs/replica_exchange.md).
//
// K replicas of one configuration, each an in-memory simulation (run/simulation.hpp) held at the
// temperature of its rung by the configuration's Andersen thermostat. Every `interval` of
// simulated time all replicas stop, and neighbouring rungs try to swap their replicas by the
// Metropolis rule (replica/exchange_rule.hpp). A replica that moves to another rung takes that
// rung's thermostat temperature and has its velocities scaled by sqrt(T_new / T_old).
//
// Replica r is `kairos run CONFIG --set system.seed=SEED+r --set system.temperature=T_r --set
// driving.temperature=T` (T_r its starting rung's, T its present rung's), so any replica's
// start can be repeated by hand. The replicas advance in threads (--workers) and, under
// mpirun, spread over the ranks (replica r on rank r mod size); every rank draws the same
// exchange decisions from the same random stream, so only the energies travel between ranks.
//
// The directory holds replica.json (what the ensemble is: the same command continues it, a
// different one is refused), exchange.tsv (one row per round: the time, each rung's energy and
// replica), checkpoint/ (every replica's restart file and ensemble.json: the exchange state),
// and at the end temperatures.tsv and summary.json (energies, heat capacities, acceptance rates,
// round trips). A stopped ensemble (SIGINT/SIGTERM after the current round, or
// run.max_wall_seconds) is continued bit for bit by the same command from its checkpoint.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace kairos {

struct ReplicaExchangeSettings {
  std::filesystem::path config;        // as given
  std::vector<std::string> overrides;  // --set, every replica
  std::string temperatures;            // the ladder as given (A:B:N, A:B:N:log, T1,T2,...)
  double interval = 0.0;               // simulated time between exchange rounds, > 0
  std::uint64_t exchanges = 0;         // rounds in all (a continued ensemble runs up to this)
  std::uint64_t equilibration = 0;     // first rounds left out of the statistics
  std::filesystem::path directory;
  int workers = 1;                    // replicas advanced at a time by this process
  double checkpoint_seconds = 300.0;  // wall time between checkpoints (and at the end)
  std::string command_line;           // for summary.json's provenance
};

// The ensemble as planned: every replica's configuration read and checked.
struct ReplicaExchangePlan {
  ReplicaExchangeSettings settings;
  std::string config_text;
  std::vector<double> temperatures;  // ascending
  std::uint64_t seed = 0;            // system.seed of the configuration
  int dimension = 3;
  double max_wall_seconds = 0.0;  // run.max_wall_seconds of the configuration
  // Replica r's overrides on rung `rung` (the settings' --set list, then its seed, starting
  // temperature and thermostat temperature).
  std::vector<std::string> replica_overrides(std::size_t r, std::size_t rung) const;
};

// Reads and checks (InputError naming the replica or the option): the configuration must use
// the event integrator with an Andersen thermostat ([driving] kind = "andersen"), the --set list
// must not give the keys the ladder sets, the numbers must be in range.
ReplicaExchangePlan plan_replica_exchange(const ReplicaExchangeSettings& settings);

// With the directory locked (SweepDirectoryLock): writes replica.json and the config's copy, or
// checks that the replica.json there describes this ensemble (--exchanges and --equilibration
// may differ: more rounds extend it). InputError naming what differs.
void claim_replica_directory(const ReplicaExchangePlan& plan);

// How the processes that hold the replicas talk: one process (this class) or MPI ranks
// (cli/sweep_mpi.cpp).
class ReplicaComm {
 public:
  virtual ~ReplicaComm() = default;
  virtual int rank() const { return 0; }
  virtual int size() const { return 1; }
  // Element-wise sum over the processes, in place (each gives its own replicas' entries and
  // zeros elsewhere).
  virtual void sum(std::vector<double>& values) const { (void)values; }
  // Whether any process says yes; every process waits for the others here.
  virtual bool any(bool yes) const { return yes; }
};

struct ReplicaExchangeOutcome {
  std::uint64_t rounds = 0;       // done in all (earlier invocations included)
  bool stopped = false;           // a stop request: the same command continues
  bool wall_limit = false;        // run.max_wall_seconds: likewise
  std::filesystem::path summary;  // summary.json (rank 0, when written)
};

// Runs (or continues) the ensemble up to settings.exchanges rounds; rank 0 writes the tables.
// InputError for a replica that cannot go on (naming it and the round).
ReplicaExchangeOutcome run_replica_exchange(const ReplicaExchangePlan& plan,
                                            const ReplicaComm& comm);

}  // namespace kairos
