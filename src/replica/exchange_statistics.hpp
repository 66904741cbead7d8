// What a replica-exchange run measured (docs/replica_exchange.md), from its exchange.tsv: per
// rung the mean configurational energy and the heat capacity from its fluctuations, per pair of
// neighbouring rungs the acceptance measured and the one the two energy distributions predict,
// per replica its round trips through the ladder. Written as temperatures.tsv and summary.json.
//
// Errors come from the rounds after the equilibration. <U>'s is the blocking estimate
// (analysis/block_average.hpp: Flyvbjerg and Petersen, J. Chem. Phys. 91, 461 (1989), the
// level chosen by Jonsson's test), which finds how many rounds the energies stay correlated.
// The heat capacity's is a jackknife (Efron and Stein, Ann. Stat. 9, 586 (1981)) over at most
// 64 contiguous blocks, each at least as long as the blocks that test found independent for U
// and for its fluctuation (U - <U>)^2. summary.json says whether both tests found a plateau.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <vector>

#include "replica/exchange_rule.hpp"
#include "run/provenance.hpp"

namespace kairos {

struct ReplicaExchangePlan;

// exchange.tsv as read back: per row (a round) the round, the time, per rung the energy and the
// replica at the end of the round's interval, and the round's swaps.
struct ExchangeResults {
  std::vector<std::uint64_t> round;
  std::vector<double> time;
  std::vector<std::vector<double>> energy_at;          // [rung][row]
  std::vector<std::vector<std::uint32_t>> replica_at;  // [rung][row], before the row's swaps
  std::vector<std::string> swaps;  // per row, per pair: '-' not attempted, '0', '1' swapped
};

ExchangeResults read_exchange_table(const std::filesystem::path& path, std::size_t rungs);

struct Estimate {
  double value = 0.0;
  double error = 0.0;  // NaN when there are too few samples for blocks
};

// `statistic` of all samples, with its jackknife error over up to `most_blocks` blocks.
Estimate jackknife(const std::vector<double>& samples,
                   const std::function<double(const std::vector<double>&)>& statistic,
                   std::size_t most_blocks = 20);

// The heat capacity in units of k at temperature T from energy samples U: kinetic_dof / 2 +
// var(U) / T^2 (the canonical kinetic part plus the configurational fluctuation).
double heat_capacity(const std::vector<double>& u, double temperature, double kinetic_dof);

// Writes temperatures.tsv and summary.json into the plan's directory (atomically); returns the
// summary's path. `kinetic_dof`: D times the particles of a replica.
std::filesystem::path write_exchange_results(const ReplicaExchangePlan& plan,
                                             const ExchangeState& state,
                                             const ExchangeResults& results, double kinetic_dof,
                                             const Provenance& provenance);

}  // namespace kairos
