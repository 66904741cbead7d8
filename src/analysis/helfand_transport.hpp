// The Einstein-Helfand transport coefficients from samples of the Helfand moments
// (engine/helfand_moments.hpp plus the engine's virial tensor) taken at regular times: the
// shear viscosity, bulk viscosity and thermal conductivity, each from the long-time slope of
// its moment's mean square on log-spaced lags with many time origins (analysis/msd.hpp, one
// "particle" per moment component), and Green-Kubo from the same samples (the autocorrelation
// of the fluxes, block-averaged over each level's spacing) as the cross-check.
// docs/physics.md#einstein-helfand-transport-coefficients.
//
// In a mixture the thermal conductivity is the heat flux's response at zero diffusion flux:
// lambda = (L_ee - L_eA L_AA^-1 L_Ae) / (V kT^2), the L the Einstein-Helfand slopes of the
// energy moment and the species' mass moments G_a (relative to the centre of mass) and of
// their cross correlations (docs/physics.md#thermal-conductivity-of-a-mixture). The cross
// correlations come from the mean squares of sums of two moments.
//
// What analysis.transport (run/outputs/transport_output.hpp) and the Python module's
// Simulation.transport compute, from the same code: no run dependency.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "analysis/msd.hpp"
#include "core/vec.hpp"

namespace kairos {

template <int D>
class HelfandTransport {
 public:
  // The moments' components, grouped: the shear estimators (the symmetrised off-diagonal
  // components and the normal-stress differences, all with the same autocorrelation in an
  // isotropic fluid), the pressure (one), the energy flux (D).
  static constexpr int kShear = D == 3 ? 5 : 2;
  // Mixtures add D components per mass moment, per (energy + mass moment) and per (mass moment
  // + mass moment), each set its own group after these.
  enum Group : std::uint32_t { kShearGroup = 0, kBulkGroup = 1, kHeatGroup = 2 };
  using Correlator = MsdCorrelator<1>;
  using Fit = std::optional<typename Correlator::Diffusion>;

  // The moments at one time: G_ab (kinetic + collisional, row-major D x D), the energy moment
  // (kinetic + collisional), and the trace of the kinetic part of G (the temperature's integral).
  struct Moments {
    std::array<double, 9> stress{};
    Vec<D> energy{};
    double kinetic_trace = 0.0;
    // Soft contacts: the time integral of the number of frozen pairs, whose relative motion
    // is not in the kinetic trace (kT counts the degrees of freedom that move).
    double frozen_pair_time = 0.0;
    // Mixtures: the mass moments G_a = sum_{i in a} m_i x_i - (M_a / M) sum_i m_i x_i
    // (unwrapped positions) of every species present but the last.
    std::vector<Vec<D>> mass;
  };

  // Samples `interval` apart of a system of `particles` particles in `volume`; a mixture's
  // `mass_moments` mass moments are scaled by `mass_scale` (an energy per mass, about kT / m:
  // the sums of moments then add terms of one size).
  HelfandTransport(double interval, std::size_t particles, double volume,
                   std::size_t mass_moments = 0, double mass_scale = 1.0);

  // The next sample, at time t.
  void add(double t, const Moments& m);

  std::uint64_t samples() const { return helfand_.samples(); }
  double interval() const { return helfand_.interval(); }
  double volume() const { return volume_; }
  double first_time() const { return first_time_; }
  double last_time() const { return last_time_; }
  // The time-averaged temperature over the samples (exact: the kinetic stress's trace), per
  // degree of freedom of the motion relative to the centre of mass (NaN before 2 samples).
  double temperature() const;

  // The Einstein-Helfand fits of the three groups over the lags in [from, to] (the bulk one
  // about the pressure's drift); nothing before 2 samples. coefficient / (V kT) (the energy's:
  // / (V kT^2)) is the transport coefficient.
  std::array<Fit, 3> einstein_helfand(double from, double to) const;
  // Green-Kubo: the flux autocorrelations integrated up to `to` (the pressure's about its
  // mean; a mixture's heat flux projected with the fits over [from, to]); nothing before 3
  // samples.
  std::array<Fit, 3> green_kubo(double from, double to) const;
  // The scale that turns a fit's coefficient of group g into the transport coefficient.
  double scale(int group) const;

  // The heat moment of a mixture: G_q = G_e - sum_a beta_a G_a with beta = L_AA^-1 L_Ae from
  // the fits over [from, to], whose mean square is that of the energy moment less its part
  // correlated with interdiffusion (first order in beta's error: beta minimises it). `weight`:
  // the combination of the correlator's groups that is <dG_q^2> (one species: the energy's).
  struct HeatProjection {
    std::vector<double> beta;  // per mass moment: an energy per mass
    double removed = 0.0;      // the fraction of L_ee removed
    std::vector<double> weight;
  };
  // Nothing when a fit is missing or L_AA is not positive definite.
  std::optional<HeatProjection> heat_projection(double from, double to) const;
  std::size_t mass_moments() const { return mass_moments_; }

  // Per lag: the three moments' mean squares (helfand.tsv: the pressure's about its drift, over
  // 1 - lag / span; lags below the sampled span; a mixture's heat moment projected with the
  // fits over [from, to]) or the flux autocorrelations (green_kubo.tsv: the pressure's about
  // its mean), and the running coefficients (Einstein-Helfand: <dG^2> / (2 lag V kT), kT^2 for
  // the conductivity; Green-Kubo: the running integrals).
  struct Row {
    double lag = 0.0;
    std::uint64_t origins = 0;
    std::array<double, 3> value{}, coefficient{};
  };
  std::vector<Row> helfand_rows(double from, double to) const;
  std::vector<Row> green_kubo_rows(double from, double to) const;

  std::size_t bytes() const { return helfand_.bytes() + fluxes_.bytes(); }

 private:
  using Components = std::vector<double>;
  Components components(const Moments& m) const;
  std::uint32_t groups() const;
  // The weights of the heat moment's mean square (one species: the energy's group alone).
  std::vector<double> heat_weight(double from, double to) const;
  double heat_value(const std::vector<double>& mean, const std::vector<double>& weight) const;
  // The drift of the pressure's moment left after the first interval's rate was removed: its
  // mean rate over the samples.
  double pressure_drift() const;

  std::size_t particles_;
  double volume_;
  std::size_t mass_moments_;
  double mass_scale_;
  std::size_t components_;
  Correlator helfand_;
  Correlator fluxes_;  // the same samples as fluxes (kFluxProduct)
  std::vector<Vec<1>> sample_;
  Components first_{}, last_{};
  double pressure_offset_ = 0.0;  // the pressure's moment's rate in the first interval
  double kinetic_trace_first_ = 0.0, kinetic_trace_last_ = 0.0;
  double frozen_pair_time_first_ = 0.0, frozen_pair_time_last_ = 0.0;
  double first_time_ = 0.0, last_time_ = 0.0;
};

}  // namespace kairos
