#include "cli/sweep_mpi.hpp"

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <thread>
#include <vector>

#include "core/error.hpp"

#ifdef KAIROS_HAVE_MPI
#include <mpi.h>
#endif

namespace kairos::cli {

int launcher_ranks() {
  for (const char* name : {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "PMIX_SIZE"}) {
    if (const char* v = std::getenv(name)) return std::max(1, std::atoi(v));
  }
  if (std::getenv("PMIX_RANK") != nullptr) return 1;
  return 0;
}

bool MpiSession::all_ready(const std::string& error) const {
  const Agreement agreement = agree(error.empty());
  if (agreement.all_ok) return true;
  if (!error.empty() && (rank() == 0 || agreement.root_ok)) {
    const std::string who = rank() == 0 ? "" : "rank " + std::to_string(rank()) + ": ";
    std::fprintf(stderr, "kairos: error: %s%s\n", who.c_str(), error.c_str());
  }
  return false;
}

#ifdef KAIROS_HAVE_MPI

bool mpi_built() {
  return true;
}

namespace {

// Messages between the ranks: a request for a point, the point (or -1: none left), a rank's
// leaving after a stop (it asks for nothing more).
constexpr int kRequestTag = 1;
constexpr int kAssignTag = 2;
constexpr int kLeaveTag = 3;

// MPI's blocking calls spin on a core while they wait; a rank waiting for rank 0 or for the
// others' runs to end would take a core from the runs.
void wait_without_spinning(MPI_Request& request, std::chrono::milliseconds poll) {
  for (;;) {
    int done = 0;
    MPI_Test(&request, &done, MPI_STATUS_IGNORE);
    if (done != 0) return;
    std::this_thread::sleep_for(poll);
  }
}

// Rank 0: the next point to whoever asks, itself included.
class Coordinator final : public SweepWork {
 public:
  Coordinator(std::size_t count, int ranks) : count_(count), open_ranks_(ranks - 1) {}

  std::optional<std::size_t> next() override {
    serve();
    if (stopped_ || next_ >= count_) return std::nullopt;
    return next_++;
  }

  // Answers every request that has arrived.
  void serve() override {
    for (;;) {
      int waiting = 0;
      MPI_Status status;
      MPI_Iprobe(MPI_ANY_SOURCE, MPI_ANY_TAG, MPI_COMM_WORLD, &waiting, &status);
      if (waiting == 0) return;
      char none = 0;
      MPI_Recv(&none, 1, MPI_CHAR, status.MPI_SOURCE, status.MPI_TAG, MPI_COMM_WORLD,
               MPI_STATUS_IGNORE);
      if (status.MPI_TAG == kLeaveTag) {
        --open_ranks_;
        continue;
      }
      long long point = -1;
      if (!stopped_ && next_ < count_) point = static_cast<long long>(next_++);
      if (point < 0) --open_ranks_;  // told that nothing is left: it asks no more
      MPI_Send(&point, 1, MPI_LONG_LONG, status.MPI_SOURCE, kAssignTag, MPI_COMM_WORLD);
    }
  }

  bool serving() const override { return open_ranks_ > 0; }
  void stop() override { stopped_ = true; }

 private:
  std::size_t count_;
  std::size_t next_ = 0;
  int open_ranks_;
  bool stopped_ = false;
};

// Any other rank: asks rank 0 for each point.
class Requester final : public SweepWork {
 public:
  std::optional<std::size_t> next() override {
    if (done_) return std::nullopt;
    char none = 0;
    MPI_Send(&none, 1, MPI_CHAR, 0, kRequestTag, MPI_COMM_WORLD);
    long long point = -1;
    MPI_Request request;
    MPI_Irecv(&point, 1, MPI_LONG_LONG, 0, kAssignTag, MPI_COMM_WORLD, &request);
    wait_without_spinning(request, std::chrono::milliseconds(2));
    if (point < 0) {
      done_ = true;
      return std::nullopt;
    }
    return static_cast<std::size_t>(point);
  }

  void stop() override {
    if (done_) return;
    done_ = true;
    char none = 0;
    MPI_Send(&none, 1, MPI_CHAR, 0, kLeaveTag, MPI_COMM_WORLD);
  }

 private:
  bool done_ = false;
};

}  // namespace

MpiSession::MpiSession(int& argc, char**& argv) {
  MPI_Init(&argc, &argv);
  MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
  MPI_Comm_size(MPI_COMM_WORLD, &size_);
}

MpiSession::~MpiSession() {
  MPI_Finalize();
}

MpiSession::Agreement MpiSession::agree(bool ok) const {
  int mine = ok ? 1 : 0, all = 0, root = mine;
  MPI_Allreduce(&mine, &all, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
  MPI_Bcast(&root, 1, MPI_INT, 0, MPI_COMM_WORLD);
  return {all != 0, root != 0};
}

void MpiSession::abort(int status) const {
  MPI_Abort(MPI_COMM_WORLD, status);
  std::_Exit(status);
}

void MpiSession::wait_for_all() const {
  MPI_Request request;
  MPI_Ibarrier(MPI_COMM_WORLD, &request);
  wait_without_spinning(request, std::chrono::milliseconds(50));
}

void MpiSession::sum(std::vector<double>& values) const {
  MPI_Request request;
  MPI_Iallreduce(MPI_IN_PLACE, values.data(), static_cast<int>(values.size()), MPI_DOUBLE, MPI_SUM,
                 MPI_COMM_WORLD, &request);
  wait_without_spinning(request, std::chrono::milliseconds(1));
}

bool MpiSession::any(bool yes) const {
  int mine = yes ? 1 : 0, all = 0;
  MPI_Request request;
  MPI_Iallreduce(&mine, &all, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD, &request);
  wait_without_spinning(request, std::chrono::milliseconds(1));
  return all != 0;
}

std::unique_ptr<SweepWork> mpi_sweep_work(const MpiSession& session, std::size_t count) {
  if (session.rank() == 0) return std::make_unique<Coordinator>(count, session.size());
  return std::make_unique<Requester>();
}

#else

bool mpi_built() {
  return false;
}

MpiSession::MpiSession(int&, char**&) {
  throw InputError(
      "kairos was started by an MPI launcher with several ranks, but was built without MPI "
      "(install libopenmpi-dev and rebuild; docs/install.md)");
}
MpiSession::~MpiSession() = default;
MpiSession::Agreement MpiSession::agree(bool ok) const {
  return {ok, ok};
}
void MpiSession::abort(int status) const {
  std::_Exit(status);
}
void MpiSession::wait_for_all() const {}
void MpiSession::sum(std::vector<double>&) const {}
bool MpiSession::any(bool yes) const {
  return yes;
}
std::unique_ptr<SweepWork> mpi_sweep_work(const MpiSession&, std::size_t count) {
  return std::make_unique<LocalSweepWork>(count);
}

#endif

}  // namespace kairos::cli
