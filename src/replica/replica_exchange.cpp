#include "replica/replica_exchange.hpp"

#include <unistd.h>
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <exception>
#include <fstream>
#include <memory>
#include <optional>
#include <sstream>
#include <thread>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "core/error.hpp"
#include "core/stop_flag.hpp"
#include "io/atomic_file.hpp"
#include "io/config.hpp"
#include "io/config_choices.hpp"
#include "io/config_obstacles.hpp"
#include "io/directory_manifest.hpp"
#include "io/line_file.hpp"
#include "io/log_file.hpp"
#include "io/progress.hpp"
#include "replica/exchange_rule.hpp"
#include "replica/exchange_statistics.hpp"
#include "run/provenance.hpp"
#include "run/simulation.hpp"

namespace kairos {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

constexpr const char* kManifest = "replica.json";
constexpr const char* kConfigCopy = "replica-config.toml";
constexpr const char* kExchangeTable = "exchange.tsv";
constexpr const char* kLogFile = "replica-exchange.log";  // what the root printed, stamped
constexpr const char* kCheckpoint = "checkpoint";
constexpr const char* kCheckpointNew = "checkpoint.new";
constexpr const char* kCheckpointOld = "checkpoint.old";
constexpr const char* kEnsembleFile = "ensemble.json";

// Shortest text that reads back as the same double.
std::string number(double x) {
  return fmt::format("{}", x);
}

std::string replica_file(std::size_t r) {
  return fmt::format("replica_{:03}.gsd", r);
}

nlohmann::json manifest(const ReplicaExchangePlan& plan) {
  return {{"kairos_replica_exchange", 1},
          {"config", fs::absolute(plan.settings.config).lexically_normal().string()},
          {"config_text", plan.config_text},
          {"set", plan.settings.overrides},
          {"temperatures", plan.temperatures},
          {"interval", plan.settings.interval}};
}

// ----- the exchange state in a checkpoint

nlohmann::json to_json(const ExchangeState& s) {
  std::ostringstream rng;
  rng << s.rng;
  return {{"round", s.round},       {"replica_at", s.replica_at}, {"attempts", s.attempts},
          {"accepted", s.accepted}, {"last_end", s.last_end},     {"round_trips", s.round_trips},
          {"rng", rng.str()}};
}

ExchangeState exchange_state_from(const nlohmann::json& j, std::size_t rungs,
                                  const fs::path& file) {
  ExchangeState s;
  try {
    s.round = j.at("round").get<std::uint64_t>();
    s.replica_at = j.at("replica_at").get<std::vector<std::uint32_t>>();
    s.attempts = j.at("attempts").get<std::vector<std::uint64_t>>();
    s.accepted = j.at("accepted").get<std::vector<std::uint64_t>>();
    s.last_end = j.at("last_end").get<std::vector<std::int8_t>>();
    s.round_trips = j.at("round_trips").get<std::vector<std::uint64_t>>();
    std::istringstream rng(j.at("rng").get<std::string>());
    rng >> s.rng;
    if (!rng) throw InputError("the random stream's state is unreadable");
  } catch (const nlohmann::json::exception& e) {
    throw InputError(fmt::format("{}: not an ensemble checkpoint: {}", file.string(), e.what()));
  } catch (const InputError& e) {
    throw InputError(fmt::format("{}: {}", file.string(), e.what()));
  }
  std::vector<std::uint32_t> sorted = s.replica_at;
  std::sort(sorted.begin(), sorted.end());
  bool permutation = sorted.size() == rungs;
  for (std::size_t k = 0; permutation && k < rungs; ++k) permutation = sorted[k] == k;
  if (!permutation || s.attempts.size() + 1 != rungs || s.accepted.size() + 1 != rungs ||
      s.last_end.size() != rungs || s.round_trips.size() != rungs) {
    throw InputError(
        fmt::format("{}: the checkpoint is not one of {} replicas", file.string(), rungs));
  }
  return s;
}

// exchange.tsv has one row per round: the checkpoint's rows are its rounds.
struct Checkpoint {
  fs::path directory;
  ExchangeState state;
};

// checkpoint/ (settle_checkpoint has made it the newest complete one), or nothing.
std::optional<Checkpoint> find_checkpoint(const fs::path& directory, std::size_t rungs) {
  const fs::path file = directory / kCheckpoint / kEnsembleFile;
  std::error_code ec;
  if (!fs::exists(file, ec)) return std::nullopt;
  std::ifstream in(file);
  const nlohmann::json j = nlohmann::json::parse(in, nullptr, /*allow_exceptions=*/false);
  if (j.is_discarded()) throw InputError(fmt::format("{}: unreadable JSON", file.string()));
  return Checkpoint{directory / kCheckpoint, exchange_state_from(j, rungs, file)};
}

// After a kill while a checkpoint was being made: makes checkpoint/ the newest complete one.
// checkpoint.new/ is complete when it holds ensemble.json (written last, after every replica's
// file); checkpoint.old/ is the previous one, kept until the new one is in place.
void settle_checkpoint(const fs::path& directory) {
  const fs::path fresh = directory / kCheckpointNew;
  const fs::path current = directory / kCheckpoint;
  const fs::path old = directory / kCheckpointOld;
  std::error_code ec;
  const auto fail = [&](const fs::path& what) {
    throw InputError(
        fmt::format("{}: cannot settle the checkpoint: {}", what.string(), ec.message()));
  };
  if (fs::exists(fresh / kEnsembleFile, ec)) {
    if (fs::exists(current, ec)) {
      fs::remove_all(old, ec);
      fs::rename(current, old, ec);
      if (ec) fail(current);
    }
    fs::rename(fresh, current, ec);
    if (ec) fail(fresh);
    sync_to_disk(directory);
  } else if (!fs::exists(current, ec) && fs::exists(old / kEnsembleFile, ec)) {
    fs::rename(old, current, ec);
    if (ec) fail(old);
    sync_to_disk(directory);
  }
  fs::remove_all(fresh, ec);
  if (fs::exists(current, ec)) fs::remove_all(old, ec);
}

// The data rows of a table written by LineFile (a torn last line not counted).
std::uint64_t complete_rows(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::uint64_t lines = 0;
  for (std::string line; std::getline(in, line);) lines += in.eof() ? 0 : 1;
  return lines > 0 ? lines - 1 : 0;
}

// ----- the replicas of this process

template <int D>
class LocalReplicas {
 public:
  LocalReplicas(const ReplicaExchangePlan& plan, const ReplicaComm& comm,
                const std::optional<Checkpoint>& checkpoint, const ExchangeState& state)
      : plan_(plan), comm_(comm) {
    const std::vector<std::uint32_t> rung = state.rung_of();
    for (std::size_t r = static_cast<std::size_t>(comm.rank()); r < state.rungs();
         r += static_cast<std::size_t>(comm.size())) {
      const Config c = replica_config(r, rung[r]);
      std::optional<fs::path> restart;
      if (checkpoint) restart = checkpoint->directory / replica_file(r);
      try {
        replicas_.push_back({r, std::make_unique<Simulation<D>>(c, restart)});
      } catch (const InputError& e) {
        throw InputError(fmt::format("replica {}: {}", r, e.what()));
      }
    }
  }

  // Every replica of this process to time t, `workers` at a time; InputError naming the first
  // replica that failed.
  void advance_to(double t, int workers) {
    std::atomic<std::size_t> next{0};
    std::vector<std::exception_ptr> errors(replicas_.size());
    auto work = [&] {
      for (std::size_t i; (i = next.fetch_add(1)) < replicas_.size();) {
        try {
          replicas_[i].sim->advance_to_time(t);
        } catch (...) {
          errors[i] = std::current_exception();
        }
      }
    };
    const auto threads = static_cast<std::size_t>(
        std::clamp<int>(workers, 1, static_cast<int>(std::max<std::size_t>(1, replicas_.size()))));
    std::vector<std::thread> pool;
    for (std::size_t w = 1; w < threads; ++w) pool.emplace_back(work);
    work();
    for (std::thread& th : pool) th.join();
    for (std::size_t i = 0; i < replicas_.size(); ++i) {
      if (!errors[i]) continue;
      try {
        std::rethrow_exception(errors[i]);
      } catch (const std::exception& e) {
        throw InputError(fmt::format("replica {} at time {}: {}", replicas_[i].index, t, e.what()));
      }
    }
  }

  // Each replica's configurational energy, summed over the processes: every rank gets all.
  std::vector<double> energies(std::size_t count) const {
    std::vector<double> u(count, 0.0);
    for (const Replica& rep : replicas_) u[rep.index] = rep.sim->potential_energy();
    comm_.sum(u);
    return u;
  }

  // A replica that changed rungs takes the new rung's thermostat and has its velocities scaled.
  void move(const std::vector<std::uint32_t>& rung_before,
            const std::vector<std::uint32_t>& rung_after, std::uint64_t round) {
    const std::vector<double>& t = plan_.temperatures;
    for (Replica& rep : replicas_) {
      const std::uint32_t from = rung_before[rep.index], to = rung_after[rep.index];
      if (from == to) continue;
      const double scale = std::sqrt(t[to] / t[from]);
      std::vector<Vec<D>> v = rep.sim->velocities();
      for (Vec<D>& vi : v) vi = scale * vi;
      try {
        rep.sim->set_velocities(v);
        rep.sim->set_thermostat_temperature(t[to]);
      } catch (const InputError& e) {
        throw InputError(fmt::format("replica {} moving to T = {} in round {}: {}", rep.index,
                                     number(t[to]), round, e.what()));
      }
    }
  }

  void save(const fs::path& directory) const {
    for (const Replica& rep : replicas_) rep.sim->save(directory / replica_file(rep.index));
  }

  std::size_t particles() const { return replicas_.empty() ? 0 : replicas_.front().sim->size(); }

 private:
  Config replica_config(std::size_t r, std::size_t rung) const {
    return parse_config(plan_.config_text, plan_.settings.config.string(),
                        plan_.replica_overrides(r, rung));
  }

  struct Replica {
    std::size_t index;
    std::unique_ptr<Simulation<D>> sim;
  };
  const ReplicaExchangePlan& plan_;
  const ReplicaComm& comm_;
  std::vector<Replica> replicas_;
};

// ----- the loop

std::string exchange_header(std::size_t rungs) {
  std::string h = "round\ttime";
  for (std::size_t k = 0; k < rungs; ++k) h += fmt::format("\tU_{}", k);
  for (std::size_t k = 0; k < rungs; ++k) h += fmt::format("\treplica_{}", k);
  return h + "\tswaps\n";
}

std::string exchange_row(std::uint64_t round, double time, const std::vector<double>& energy_at,
                         const std::vector<std::uint32_t>& replica_at, const std::string& swaps) {
  std::string row = fmt::format("{}\t{}", round, number(time));
  for (const double u : energy_at) {
    row += '\t';
    row += number(u);
  }
  for (const std::uint32_t r : replica_at) row += fmt::format("\t{}", r);
  row += '\t';
  row += swaps;
  row += '\n';
  return row;
}

// Every process saves its replicas into checkpoint.new/, then rank 0 adds ensemble.json (the
// exchange table synced first: its row of every round up to this one is on disk) and makes it the
// checkpoint, removing the previous one only once the new one is in place: a kill at any moment
// leaves a complete checkpoint that settle_checkpoint finds.
template <int D>
void write_checkpoint(const fs::path& directory, const LocalReplicas<D>& replicas,
                      const ExchangeState& state, LineFile* table, const ReplicaComm& comm) {
  const fs::path fresh = directory / kCheckpointNew;
  const fs::path current = directory / kCheckpoint;
  const fs::path old = directory / kCheckpointOld;
  std::string error;
  if (comm.rank() == 0) {
    std::error_code ec;
    fs::remove_all(fresh, ec);
    fs::create_directories(fresh, ec);
    if (ec) error = fmt::format("{}: cannot create: {}", fresh.string(), ec.message());
  }
  if (comm.any(!error.empty())) {
    throw InputError(error.empty() ? "the checkpoint directory could not be made" : error);
  }
  try {
    replicas.save(fresh);
  } catch (const std::exception& e) {
    error = e.what();
  }
  if (comm.any(!error.empty())) {
    throw InputError(error.empty() ? "another rank could not write its replicas" : error);
  }
  if (comm.rank() == 0) {
    table->sync();
    write_text_atomically(fresh / kEnsembleFile, to_json(state).dump(1) + "\n");
    sync_to_disk(fresh);
    std::error_code ec;
    fs::remove_all(old, ec);
    if (fs::exists(current, ec)) fs::rename(current, old, ec);
    if (!ec) fs::rename(fresh, current, ec);
    if (ec) {
      throw InputError(
          fmt::format("{}: cannot make it the checkpoint: {}", fresh.string(), ec.message()));
    }
    sync_to_disk(directory);
    fs::remove_all(old, ec);
  }
  (void)comm.any(false);  // the checkpoint is in place before any process goes on
}

std::string acceptance_text(const ExchangeState& s) {
  std::string out;
  for (std::size_t k = 0; k < s.attempts.size(); ++k) {
    out += k == 0 ? "" : " ";
    out += s.attempts[k] == 0 ? "-"
                              : fmt::format("{:.2f}", static_cast<double>(s.accepted[k]) /
                                                          static_cast<double>(s.attempts[k]));
  }
  return out;
}

template <int D>
ReplicaExchangeOutcome run_ensemble(const ReplicaExchangePlan& plan, const ReplicaComm& comm) {
  const ReplicaExchangeSettings& settings = plan.settings;
  const std::size_t rungs = plan.temperatures.size();
  const bool root = comm.rank() == 0;
  const std::optional<Checkpoint> checkpoint = find_checkpoint(settings.directory, rungs);
  ExchangeState state = checkpoint ? checkpoint->state : ExchangeState::start(rungs, plan.seed);
  if (state.round > settings.exchanges) {
    throw InputError(fmt::format(
        "--exchanges {}: the ensemble in {} has done {} rounds already; give at least that many",
        settings.exchanges, settings.directory.string(), state.round));
  }
  LocalReplicas<D> replicas(plan, comm, checkpoint, state);
  std::optional<LineFile> table;
  LogFile log;
  // A line on stdout and in the log (the root's).
  const auto say = [&](const std::string& line) {
    fmt::print("{}\n", line);
    std::fflush(stdout);
    log.line(line);
  };
  if (root) {
    log.open(settings.directory / kLogFile);
    const fs::path path = settings.directory / kExchangeTable;
    // Cut back to the checkpoint's rounds (claim_replica_directory refused a table with fewer).
    table.emplace(path, exchange_header(rungs), state.round);
    say(
        fmt::format("kairos replica-exchange: {} replicas of {} particles ({}D) at T = {} .. {}, "
                    "{}{} rounds of {} time units, in {}/",
                    rungs, replicas.particles(), D, number(plan.temperatures.front()),
                    number(plan.temperatures.back()),
                    checkpoint ? fmt::format("continuing at round {} of ", state.round) : "",
                    settings.exchanges, number(settings.interval), settings.directory.string()));
  }

  ReplicaExchangeOutcome outcome;
  const auto start = Clock::now();
  auto last_checkpoint = start, last_line = start;
  const std::uint64_t first_round = state.round;
  auto seconds_since = [](Clock::time_point t) {
    return std::chrono::duration<double>(Clock::now() - t).count();
  };
  while (state.round < settings.exchanges) {
    const double t = static_cast<double>(state.round + 1) * settings.interval;
    replicas.advance_to(t, settings.workers);
    const std::vector<double> u = replicas.energies(rungs);
    std::vector<double> energy_at(rungs);
    for (std::size_t k = 0; k < rungs; ++k) energy_at[k] = u[state.replica_at[k]];
    const std::vector<std::uint32_t> replica_at = state.replica_at, before = state.rung_of();
    const std::string swaps = attempt_exchanges(state, plan.temperatures, energy_at);
    if (table) table->append(exchange_row(state.round, t, energy_at, replica_at, swaps));
    replicas.move(before, state.rung_of(), state.round);

    const bool wall = plan.max_wall_seconds > 0.0 && seconds_since(start) >= plan.max_wall_seconds;
    const bool stop = comm.any(stop_requested() || wall);
    if (stop) {
      outcome.wall_limit = comm.any(wall);
      outcome.stopped = !outcome.wall_limit;
    }
    const bool due = seconds_since(last_checkpoint) >= settings.checkpoint_seconds;
    if (stop || state.round == settings.exchanges || comm.any(due)) {
      write_checkpoint(settings.directory, replicas, state, table ? &*table : nullptr, comm);
      last_checkpoint = Clock::now();
    }
    if (root && (seconds_since(last_line) >= 10.0 || state.round == settings.exchanges)) {
      const double rate =
          static_cast<double>(state.round - first_round) / std::max(1e-9, seconds_since(start));
      say(fmt::format(
          "kairos replica-exchange: round {}/{}, t = {}, {:.3g} rounds/s, ETA {}, "
          "acceptance {}",
          state.round, settings.exchanges, number(t), rate,
          format_duration(rate > 0.0 ? static_cast<double>(settings.exchanges - state.round) / rate
                                     : -1.0),
          acceptance_text(state)));
      last_line = Clock::now();
    }
    if (stop) break;
  }
  outcome.rounds = state.round;
  if (root) {
    log.line(fmt::format("end: {} after {} rounds of {}; {} of wall time",
                         outcome.wall_limit ? "run.max_wall_seconds reached"
                         : outcome.stopped  ? "stopped by a signal"
                                            : "completed",
                         state.round, settings.exchanges, format_duration(seconds_since(start))));
  }
  if (root && state.round == settings.exchanges && state.round > 0) {
    ExchangeResults results = read_exchange_table(settings.directory / kExchangeTable, rungs);
    outcome.summary =
        write_exchange_results(plan, state, results, static_cast<double>(D * replicas.particles()),
                               provenance_now(settings.command_line, std::nullopt));
  }
  return outcome;
}

}  // namespace

std::vector<std::string> ReplicaExchangePlan::replica_overrides(std::size_t r,
                                                                std::size_t rung) const {
  std::vector<std::string> o = settings.overrides;
  o.push_back(fmt::format("system.seed={}", seed + r));
  o.push_back("system.temperature=" + number(temperatures[r]));
  o.push_back("driving.temperature=" + number(temperatures[rung]));
  return o;
}

ReplicaExchangePlan plan_replica_exchange(const ReplicaExchangeSettings& settings) {
  if (settings.directory.empty()) throw InputError("-o/--output: the directory must not be empty");
  if (!std::isfinite(settings.interval) || !(settings.interval > 0.0)) {
    throw InputError(
        fmt::format("--interval: must be a finite time > 0, got {}", number(settings.interval)));
  }
  if (settings.exchanges < 1) throw InputError("--exchanges: must be at least 1");
  if (settings.equilibration >= settings.exchanges) {
    throw InputError(fmt::format(
        "--equilibration {}: must be fewer than --exchanges {} (the rounds left for statistics)",
        settings.equilibration, settings.exchanges));
  }
  if (settings.workers < 1 || settings.workers > 4096) {
    throw InputError(fmt::format("--workers: must be in [1, 4096], got {}", settings.workers));
  }
  if (!std::isfinite(settings.checkpoint_seconds) || !(settings.checkpoint_seconds >= 0.0)) {
    throw InputError("--checkpoint-seconds: must be a finite number >= 0");
  }
  for (const std::string& s : settings.overrides) {
    const std::string key = s.substr(0, s.find('='));
    for (const char* own : {"system.temperature", "driving.temperature"}) {
      if (key == own) {
        throw InputError(fmt::format(
            "--set {}: replica exchange sets {} for each replica from the ladder; give the "
            "temperatures by --temperatures",
            s, own));
      }
    }
  }
  ReplicaExchangePlan plan;
  plan.settings = settings;
  plan.temperatures = parse_temperature_ladder(settings.temperatures, "--temperatures");
  if (plan.temperatures.size() > 4096) {
    throw InputError("--temperatures: more than 4096 replicas");
  }
  plan.config_text = read_config_text(settings.config);
  const Config base = parse_config(plan.config_text, settings.config.string(), settings.overrides);
  if (integrators().at(base.run.integrator) != IntegratorKind::kEvent) {
    throw InputError(
        fmt::format("run.integrator = \"{}\": replica exchange runs the event integrator",
                    base.run.integrator));
  }
  if (!driving_kinds().is(base.driving.kind, DrivingKind::kAndersen)) {
    throw InputError(fmt::format(
        "driving.kind = \"{}\": replica exchange holds each replica at its rung's temperature "
        "with the Andersen thermostat; add [driving] kind = \"andersen\" (and its rate) to the "
        "config",
        base.driving.kind));
  }
  if (const std::optional<TransportObstacle> o = replica_exchange_obstacle(base)) {
    throw InputError(
        fmt::format("{}: replica exchange needs each replica to sample the canonical "
                    "distribution of its temperature: {}",
                    o->key, o->why));
  }
  plan.seed = base.system.seed;
  plan.dimension = base.system.dimension;
  plan.max_wall_seconds = base.run.max_wall_seconds;
  for (std::size_t r = 0; r < plan.temperatures.size(); ++r) {
    try {
      (void)parse_config(plan.config_text, settings.config.string(), plan.replica_overrides(r, r));
    } catch (const InputError& e) {
      throw InputError(
          fmt::format("replica {} (T = {}): {}", r, number(plan.temperatures[r]), e.what()));
    }
  }
  return plan;
}

void claim_replica_directory(const ReplicaExchangePlan& plan) {
  const fs::path& dir = plan.settings.directory;
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec || !fs::is_directory(dir)) {
    throw InputError(fmt::format("{}: cannot create the directory: {}", dir.string(),
                                 ec ? ec.message() : "not a directory"));
  }
  const fs::path path = dir / kManifest;
  const nlohmann::json want = manifest(plan);
  if (!fs::exists(path, ec)) {
    if (fs::exists(dir / kCheckpoint, ec) || fs::exists(dir / kExchangeTable, ec)) {
      throw InputError(
          fmt::format("{}: holds an exchange table or checkpoint but no {}; give another directory",
                      dir.string(), kManifest));
    }
    write_text_atomically(dir / kConfigCopy, plan.config_text);
    write_text_atomically(path, want.dump(2) + "\n");
    return;
  }
  const nlohmann::json have = read_manifest(path, "replica-exchange", "kairos_replica_exchange");
  require_same_manifest(
      have, want,
      {{"config_text", "config text",
        [](const nlohmann::json& had) { return had.value("config", std::string("?")); }, nullptr},
       {"set", "set", {}, nullptr},
       {"temperatures", "temperatures", {}, nullptr},
       {"interval", "interval", {}, nullptr}},
      dir, "ensemble");
  settle_checkpoint(dir);
  if (const std::optional<Checkpoint> c = find_checkpoint(dir, plan.temperatures.size())) {
    const fs::path table = dir / kExchangeTable;
    if (complete_rows(table) < c->state.round) {
      throw InputError(fmt::format(
          "{}: holds {} rows, fewer than the {} of the checkpoint it continues (edited or cut?); "
          "start the ensemble afresh in another directory",
          table.string(), complete_rows(table), c->state.round));
    }
  }
}

ReplicaExchangeOutcome run_replica_exchange(const ReplicaExchangePlan& plan,
                                            const ReplicaComm& comm) {
  return plan.dimension == 2 ? run_ensemble<2>(plan, comm) : run_ensemble<3>(plan, comm);
}

}  // namespace kairos
