// A sweep across MPI ranks (`mpirun -np N kairos sweep ...`, docs/sweeps.md). Rank 0
// coordinates: it hands out the next point to whichever rank asks (dynamic load balance: a rank
// whose run ends early takes the next one) and runs points itself meanwhile; every rank runs its
// points as child processes, one at a time unless --workers says more. Rank 0 alone writes
// sweep.json and the results table. Compiled with MPI when CMake finds it (KAIROS_HAVE_MPI);
// without, a sweep started by mpirun with more than one rank is refused.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "sweep/sweep_runner.hpp"

namespace kairos::cli {

// Whether an MPI launcher started this process (mpirun's environment: OMPI_COMM_WORLD_SIZE,
// PMI_SIZE or PMIX_RANK), and with how many ranks (0: not under MPI).
int launcher_ranks();

// Whether this kairos was built with MPI.
bool mpi_built();

// MPI for the lifetime of the object (MPI_Init ... MPI_Finalize).
class MpiSession {
 public:
  MpiSession(int& argc, char**& argv);
  ~MpiSession();
  MpiSession(const MpiSession&) = delete;
  MpiSession& operator=(const MpiSession&) = delete;
  int rank() const { return rank_; }
  int size() const { return size_; }
  // Whether every rank is ready (each planned the sweep; rank 0 also claimed the directory).
  struct Agreement {
    bool all_ok = true;
    bool root_ok = true;
  };
  Agreement agree(bool ok) const;
  // agree(error.empty()); when some rank failed, prints rank 0's error (or, when rank 0 is
  // ready, each failing rank's, prefixed with its rank) and returns false.
  bool all_ready(const std::string& error) const;
  // Ends every rank of the job with this status (an error after the agreement).
  [[noreturn]] void abort(int status) const;
  // Waits for every rank without spinning: a rank whose runs have ended would otherwise take a
  // core from the others' runs in MPI's busy-waiting barrier (or MPI_Finalize).
  void wait_for_all() const;
  // Element-wise sum over the ranks, in place; whether any rank says yes. Both wait for every
  // rank without spinning (replica exchange: a rank whose replicas are ahead waits here).
  void sum(std::vector<double>& values) const;
  bool any(bool yes) const;

 private:
  int rank_ = 0;
  int size_ = 1;
};

// The work source of one rank: rank 0's coordinator, any other rank's requests to it.
std::unique_ptr<SweepWork> mpi_sweep_work(const MpiSession& session, std::size_t count);

}  // namespace kairos::cli
