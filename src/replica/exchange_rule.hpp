// Replica exchange in temperature (parallel tempering; docs/replica_exchange.md): the ladder of
// temperatures ("rungs"), which replica sits on which rung, and the Metropolis rule that swaps
// the replicas of neighbouring rungs.
//
// A swap of the configurations at rungs k and l (inverse temperatures b_k, b_l, configurational
// energies U_k, U_l) is accepted with probability min(1, exp((b_k - b_l) (U_k - U_l)))
// (Swendsen and Wang, Phys. Rev. Lett. 57, 2607 (1986); Hukushima and Nemoto, J. Phys. Soc. Jpn.
// 65, 1604 (1996)): the product of the canonical weights of the two rungs then stays the
// stationary distribution. Round r attempts the pairs (k, k + 1) with k = r mod 2, r mod 2 + 2,
// ... (even and odd pairs in turn, each pair's decision independent of the others'), and draws
// one uniform number per attempt whatever the outcome, so the random stream depends only on
// the round count.
#pragma once

#include <cstdint>
#include <random>
#include <string>
#include <vector>

namespace kairos {

// min(1, exp((beta_k - beta_l) (u_k - u_l))).
double exchange_acceptance(double beta_k, double beta_l, double u_k, double u_l);

struct ExchangeState {
  std::uint64_t round = 0;                // rounds done (each ends with its attempts)
  std::vector<std::uint32_t> replica_at;  // per rung: the replica on it
  std::vector<std::uint64_t> attempts;    // per neighbour pair (k, k + 1)
  std::vector<std::uint64_t> accepted;    // likewise
  // Per replica: where it is on its way (-1 not yet on the coldest rung, 0 on it or on its way
  // up from it, 1 reached the hottest rung since) and its round trips (coldest -> hottest ->
  // coldest) so far.
  std::vector<std::int8_t> last_end;
  std::vector<std::uint64_t> round_trips;
  std::mt19937_64 rng;

  // Replica r on rung r, nothing attempted; the random stream from `seed`.
  static ExchangeState start(std::size_t rungs, std::uint64_t seed);
  std::size_t rungs() const { return replica_at.size(); }
  // The rung of each replica (the inverse of replica_at).
  std::vector<std::uint32_t> rung_of() const;
};

// One round's attempts (see the file's comment) with energy_at[k] the configurational energy of
// the replica on rung k; updates the assignment, the counters and the round trips, and advances
// state.round. `temperatures` ascending, as many as rungs. Returns per pair (k, k + 1) '-' (not
// attempted this round), '0' (rejected) or '1' (swapped).
std::string attempt_exchanges(ExchangeState& state, const std::vector<double>& temperatures,
                              const std::vector<double>& energy_at);

// The ladder from the command line's form: A:B:N (evenly spaced), A:B:N:log (geometric, the
// usual choice: equal acceptance for a constant heat capacity) or T1,T2,... InputError (naming
// `what`) unless there are at least two, all finite, > 0 and strictly ascending.
std::vector<double> parse_temperature_ladder(const std::string& spec, const std::string& what);

// The acceptance the energy distributions of two rungs predict: the mean of
// exchange_acceptance over pairs of samples (u_k from the first, u_l from the second), each list
// thinned to at most `most` evenly strided samples. The measured rate agrees with it when the
// replicas sample their rungs' canonical distributions.
double predicted_acceptance(double beta_k, double beta_l, const std::vector<double>& u_k,
                            const std::vector<double>& u_l, std::size_t most = 1000);

}  // namespace kairos
