#include "analysis/msd.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace kairos {

template <int D>
MsdCorrelator<D>::MsdCorrelator(std::vector<std::uint32_t> group, std::uint32_t groups,
                                double interval, Statistic statistic, int max_levels)
    : group_(std::move(group)),
      groups_(groups),
      interval_(interval),
      statistic_(statistic),
      max_levels_(max_levels),
      group_size_(static_cast<std::size_t>(groups) * kSubsets, 0) {
  if (!(interval > 0.0)) throw std::invalid_argument("MsdCorrelator: interval must be > 0");
  for (std::size_t k = 0; k < group_.size(); ++k) {
    if (group_[k] >= groups_) throw std::invalid_argument("MsdCorrelator: group out of range");
    ++group_size_[slot(group_[k], static_cast<int>(k % kSubsets))];
  }
}

template <int D>
void MsdCorrelator<D>::correlate(Level& level, const std::vector<Vec<D>>& x, int first_j,
                                 std::size_t epoch, double spacing) {
  const std::size_t n = group_.size();
  const std::size_t per_j = static_cast<std::size_t>(groups_) * kSubsets;
  const bool flux = statistic_ == Statistic::kFluxProduct;
  const bool product = statistic_ != Statistic::kDisplacement;
  // A flux needs the sample before: the level's last kept one (none yet: nothing to pair).
  if (flux && level.kept == 0) return;
  const auto kept_at = [&](std::uint64_t back) {  // the sample `back` before the current one
    return &level.ring[((level.kept - back) % kPoints) * n];
  };
  const double per_time = 1.0 / (spacing * interval_);
  if (flux) {
    flux_now_.resize(n);
    const Vec<D>* before = kept_at(1);
    for (std::size_t k = 0; k < n; ++k)
      for (int a = 0; a < D; ++a) flux_now_[k][a] = (x[k][a] - before[k][a]) * per_time;
  }
  const Vec<D>* now = flux ? flux_now_.data() : x.data();
  for (int j = first_j; j < kPoints; ++j) {
    // The sample j before, and for a flux the one before it too, still in the ring.
    const auto needed = static_cast<std::uint64_t>(flux ? j + 1 : j);
    if (level.kept < needed) break;
    const Vec<D>* then = j == 0 ? x.data() : kept_at(static_cast<std::uint64_t>(j));
    const Vec<D>* then_before = flux ? kept_at(static_cast<std::uint64_t>(j) + 1) : nullptr;
    double* s2 = &level.sum2[static_cast<std::size_t>(j) * per_j];
    double* s4 = &level.sum4[static_cast<std::size_t>(j) * per_j];
    const std::size_t je = static_cast<std::size_t>(j) * kEpochs + epoch;
    double* in_epoch = &level.epoch_sum[je * groups_];
    double* s1 = &level.sum1[static_cast<std::size_t>(j) * per_j * D];
    double* in_epoch1 = &level.epoch_sum1[je * groups_ * D];
    for (std::size_t k = 0; k < n; ++k) {
      const std::size_t at = slot(group_[k], static_cast<int>(k % kSubsets));
      double r2 = 0.0;
      for (int a = 0; a < D; ++a) {
        double first;
        if (product) {
          const double earlier =
              flux ? (j == 0 ? now[k][a] : (then[k][a] - then_before[k][a]) * per_time)
                   : then[k][a];
          r2 += now[k][a] * earlier;
          first = now[k][a] + earlier;
        } else {
          first = x[k][a] - then[k][a];
          r2 += first * first;
        }
        s1[at * D + a] += first;
        in_epoch1[group_[k] * D + a] += first;
      }
      s2[at] += r2;
      s4[at] += r2 * r2;
      in_epoch[group_[k]] += r2;
    }
    ++level.count[static_cast<std::size_t>(j)];
    ++level.epoch_count[je];
  }
}

template <int D>
void MsdCorrelator<D>::add(const std::vector<Vec<D>>& position) {
  const std::size_t n = group_.size();
  if (position.size() != n) throw std::invalid_argument("MsdCorrelator: wrong particle count");
  if (samples_ / epoch_length_ >= static_cast<std::uint64_t>(kEpochs)) merge_epochs();
  const auto epoch = static_cast<std::size_t>(samples_ / epoch_length_);
  std::uint64_t spacing = 1;
  for (int l = 0; l < max_levels_; ++l, spacing *= kRatio) {
    if (samples_ % spacing != 0) break;
    if (levels_.size() <= static_cast<std::size_t>(l)) {
      // Level l begins at sample m^l (the first multiple after 0), with sample 0 taken from
      // the level below, which still keeps it (m <= kPoints).
      if (samples_ == 0 && l > 0) break;
      Level level;
      level.ring.resize(static_cast<std::size_t>(kPoints) * n);
      const std::size_t cells = static_cast<std::size_t>(kPoints) * groups_ * kSubsets;
      level.sum2.assign(cells, 0.0);
      level.sum4.assign(cells, 0.0);
      level.sum1.assign(cells * D, 0.0);
      level.count.assign(kPoints, 0);
      level.epoch_sum.assign(static_cast<std::size_t>(kPoints) * kEpochs * groups_, 0.0);
      level.epoch_sum1.assign(static_cast<std::size_t>(kPoints) * kEpochs * groups_ * D, 0.0);
      level.epoch_count.assign(static_cast<std::size_t>(kPoints) * kEpochs, 0);
      if (l > 0) {
        const Level& below = levels_[static_cast<std::size_t>(l - 1)];
        std::copy(below.ring.begin(), below.ring.begin() + static_cast<std::ptrdiff_t>(n),
                  level.ring.begin());
        level.kept = 1;
      }
      levels_.push_back(std::move(level));
    }
    Level& level = levels_[static_cast<std::size_t>(l)];
    correlate(level, position, first_lag(l), epoch, static_cast<double>(spacing));
    std::copy(position.begin(), position.end(),
              level.ring.begin() + static_cast<std::ptrdiff_t>((level.kept % kPoints) * n));
    ++level.kept;
  }
  ++samples_;
}

// Epochs 2e and 2e + 1 become epoch e: the run's origins in half as many, twice as long.
template <int D>
void MsdCorrelator<D>::merge_epochs() {
  for (Level& level : levels_) {
    for (int j = 0; j < kPoints; ++j) {
      const std::size_t base = static_cast<std::size_t>(j) * kEpochs;
      for (int e = 0; e < kEpochs / 2; ++e) {
        const std::size_t to = base + e, a = base + 2 * e, b = a + 1;
        level.epoch_count[to] = level.epoch_count[a] + level.epoch_count[b];
        for (std::uint32_t g = 0; g < groups_; ++g)
          level.epoch_sum[to * groups_ + g] =
              level.epoch_sum[a * groups_ + g] + level.epoch_sum[b * groups_ + g];
        for (std::size_t c = 0; !level.epoch_sum1.empty() && c < groups_ * D; ++c)
          level.epoch_sum1[to * groups_ * D + c] =
              level.epoch_sum1[a * groups_ * D + c] + level.epoch_sum1[b * groups_ * D + c];
      }
      for (int e = kEpochs / 2; e < kEpochs; ++e) {
        level.epoch_count[base + e] = 0;
        for (std::uint32_t g = 0; g < groups_; ++g) level.epoch_sum[(base + e) * groups_ + g] = 0.0;
        for (std::size_t c = 0; !level.epoch_sum1.empty() && c < groups_ * D; ++c)
          level.epoch_sum1[(base + e) * groups_ * D + c] = 0.0;
      }
    }
  }
  epoch_length_ *= 2;
}

template <int D>
std::vector<typename MsdCorrelator<D>::Lag> MsdCorrelator<D>::lags() const {
  std::vector<Lag> out;
  const std::size_t per_j = static_cast<std::size_t>(groups_) * kSubsets;
  double spacing = 1.0;
  for (std::size_t l = 0; l < levels_.size(); ++l, spacing *= kRatio) {
    const Level& level = levels_[l];
    for (int j = first_lag(static_cast<int>(l)); j < kPoints; ++j) {
      const std::uint64_t origins = level.count[static_cast<std::size_t>(j)];
      if (origins == 0) continue;
      Lag lag;
      lag.lag = j * spacing * interval_;
      lag.origins = origins;
      lag.mean.assign(groups_, 0.0);
      lag.non_gaussian.assign(groups_, 0.0);
      lag.subset_mean.assign(groups_, {});
      lag.epoch_mean.assign(groups_, {});
      const bool linear = !level.sum1.empty();
      if (linear) {
        lag.mean_linear.assign(groups_, Vec<D>{});
        lag.subset_mean_linear.assign(groups_, {});
        lag.epoch_mean_linear.assign(groups_, {});
      }
      const double* s2 = &level.sum2[static_cast<std::size_t>(j) * per_j];
      const double* s4 = &level.sum4[static_cast<std::size_t>(j) * per_j];
      const double* s1 = linear ? &level.sum1[static_cast<std::size_t>(j) * per_j * D] : nullptr;
      for (std::uint32_t g = 0; g < groups_; ++g) {
        double a2 = 0.0, a4 = 0.0, members = 0.0;
        Vec<D> a1{};
        for (int s = 0; s < kSubsets; ++s) {
          const std::size_t at = slot(g, s);
          const auto size = static_cast<double>(group_size_[at]);
          const double per = size > 0 ? 1.0 / (size * static_cast<double>(origins)) : 0.0;
          lag.subset_mean[g][s] = s2[at] * per;
          a2 += s2[at];
          a4 += s4[at];
          members += size;
          for (int a = 0; linear && a < D; ++a) {
            lag.subset_mean_linear[g][s][a] = s1[at * D + a] * per;
            a1[a] += s1[at * D + a];
          }
        }
        if (members == 0) continue;
        for (int e = 0; e < kEpochs; ++e) {
          const std::size_t je = static_cast<std::size_t>(j) * kEpochs + e;
          const auto n_e = static_cast<double>(level.epoch_count[je]);
          lag.epoch_mean[g][e] =
              n_e > 0 ? level.epoch_sum[je * groups_ + g] / (members * n_e) : std::nan("");
          for (int a = 0; linear && a < D; ++a) {
            lag.epoch_mean_linear[g][e][a] =
                n_e > 0 ? level.epoch_sum1[(je * groups_ + g) * D + a] / (members * n_e)
                        : std::nan("");
          }
        }
        for (int a = 0; linear && a < D; ++a)
          lag.mean_linear[g][a] = a1[a] / (members * static_cast<double>(origins));
        const double m2 = a2 / (members * static_cast<double>(origins));
        const double m4 = a4 / (members * static_cast<double>(origins));
        lag.mean[g] = m2;
        if (statistic_ == Statistic::kDisplacement)
          lag.non_gaussian[g] = m2 > 0.0 ? D * m4 / ((D + 2.0) * m2 * m2) - 1.0 : 0.0;
      }
      out.push_back(std::move(lag));
    }
  }
  return out;
}

namespace {

// Least-squares slope of y against x.
double slope(const std::vector<double>& x, const std::vector<double>& y) {
  const auto n = static_cast<double>(x.size());
  double mx = 0.0, my = 0.0;
  for (std::size_t k = 0; k < x.size(); ++k) {
    mx += x[k];
    my += y[k];
  }
  mx /= n;
  my /= n;
  double sxy = 0.0, sxx = 0.0;
  for (std::size_t k = 0; k < x.size(); ++k) {
    sxy += (x[k] - mx) * (y[k] - my);
    sxx += (x[k] - mx) * (x[k] - mx);
  }
  return sxy / sxx;
}

// The standard error of the mean of independent estimates (NaN for fewer than 2).
double standard_error(const std::vector<double>& x) {
  if (x.size() < 2) return std::nan("");
  const auto n = static_cast<double>(x.size());
  double mean = 0.0;
  for (double v : x) mean += v / n;
  double squares = 0.0;
  for (double v : x) squares += (v - mean) * (v - mean);
  return std::sqrt(squares / (n - 1.0) / n);
}

// The error bars of a coefficient from its estimates per particle subset and per time epoch:
// each one's standard error, and the larger of the two (NaN: fewer than 2 estimates).
template <class Diffusion>
void set_errors(Diffusion& d, const std::vector<double>& by_subset,
                const std::vector<double>& by_epoch) {
  d.particle_stderr = standard_error(by_subset);
  d.epoch_stderr = standard_error(by_epoch);
  d.epochs = static_cast<int>(by_epoch.size());
  d.stderr_ = std::isnan(d.epoch_stderr)      ? d.particle_stderr
              : std::isnan(d.particle_stderr) ? d.epoch_stderr
                                              : std::max(d.particle_stderr, d.epoch_stderr);
}

}  // namespace

template <int D>
std::vector<std::optional<typename MsdCorrelator<D>::Diffusion>> MsdCorrelator<D>::diffusion(
    double from, double to) const {
  return diffusion(from, to, {}, 0.0);
}

template <int D>
std::vector<std::optional<typename MsdCorrelator<D>::Diffusion>> MsdCorrelator<D>::diffusion(
    double from, double to, const std::vector<Vec<D>>& drift, double span) const {
  const std::vector<Lag> all = lags();
  std::vector<std::optional<Diffusion>> out(groups_);
  for (std::uint32_t g = 0; g < groups_; ++g) {
    // <|dx - u lag|^2> = <|dx|^2> - 2 lag u.<dx> + lag^2 |u|^2, over the bias 1 - lag / span.
    const bool drifts = g < drift.size() && statistic_ == Statistic::kDisplacement;
    const auto about_drift = [&](double lag, double square, const Vec<D>& mean) {
      if (!drifts) return square;
      const Vec<D>& u = drift[g];
      const double value = square - 2.0 * lag * dot(u, mean) + lag * lag * dot(u, u);
      return span > 0.0 ? value / (1.0 - lag / span) : value;
    };
    const auto mean_of = [&](const Lag& lag) { return drifts ? lag.mean_linear[g] : Vec<D>{}; };
    std::vector<double> t, y;
    std::array<std::vector<double>, kSubsets> ys;
    for (const Lag& lag : all) {
      if (lag.lag < from || lag.lag > to) continue;
      if (drifts && span > 0.0 && !(lag.lag < span)) continue;
      t.push_back(lag.lag);
      y.push_back(about_drift(lag.lag, lag.mean[g], mean_of(lag)));
      for (int s = 0; s < kSubsets; ++s)
        ys[s].push_back(about_drift(lag.lag, lag.subset_mean[g][s],
                                    drifts ? lag.subset_mean_linear[g][s] : Vec<D>{}));
    }
    if (t.size() < 3 || members(g) == 0) continue;  // nothing to fit, or nobody in the group
    Diffusion d;
    d.lags = static_cast<int>(t.size());
    d.coefficient = slope(t, y) / (2.0 * D);
    std::vector<double> by_subset, by_epoch;
    for (int s = 0; s < kSubsets; ++s)
      if (group_size_[slot(g, s)] > 0) by_subset.push_back(slope(t, ys[s]) / (2.0 * D));
    for (int e = 0; e < kEpochs; ++e) {
      std::vector<double> te, ye;
      for (const Lag& lag : all) {
        if (lag.lag < from || lag.lag > to || std::isnan(lag.epoch_mean[g][e])) continue;
        if (drifts && span > 0.0 && !(lag.lag < span)) continue;
        te.push_back(lag.lag);
        ye.push_back(about_drift(lag.lag, lag.epoch_mean[g][e],
                                 drifts ? lag.epoch_mean_linear[g][e] : Vec<D>{}));
      }
      if (te.size() >= 3) by_epoch.push_back(slope(te, ye) / (2.0 * D));
    }
    set_errors(d, by_subset, by_epoch);
    out[g] = d;
  }
  return out;
}

template <int D>
std::vector<std::optional<typename MsdCorrelator<D>::Diffusion>> MsdCorrelator<D>::green_kubo(
    double to) const {
  return green_kubo(to, {});
}

template <int D>
std::vector<std::optional<typename MsdCorrelator<D>::Diffusion>> MsdCorrelator<D>::green_kubo(
    double to, const std::vector<Vec<D>>& mean) const {
  const std::vector<Lag> all = lags();
  std::vector<std::optional<Diffusion>> out(groups_);
  if (statistic_ == Statistic::kDisplacement) return out;
  for (std::uint32_t g = 0; g < groups_; ++g) {
    const bool about_mean = g < mean.size();
    const auto c = [&](double product, const Vec<D>& linear) {
      if (!about_mean) return product;
      return product - dot(mean[g], linear) + dot(mean[g], mean[g]);
    };
    const auto at = [&](const Lag& lag) {
      return c(lag.mean[g], about_mean ? lag.mean_linear[g] : Vec<D>{});
    };
    const auto subset_at = [&](const Lag& lag, int s) {
      return c(lag.subset_mean[g][s], about_mean ? lag.subset_mean_linear[g][s] : Vec<D>{});
    };
    double total = 0.0;
    std::array<double, kSubsets> part{};
    int used_lags = 0;
    for (std::size_t k = 1; k < all.size() && all[k].lag <= to; ++k) {
      const double h = 0.5 * (all[k].lag - all[k - 1].lag);
      total += h * (at(all[k]) + at(all[k - 1]));
      for (int s = 0; s < kSubsets; ++s)
        part[s] += h * (subset_at(all[k], s) + subset_at(all[k - 1], s));
      ++used_lags;
    }
    if (used_lags < 2 || all.empty() || all[0].lag != 0.0 || members(g) == 0) continue;
    // The same integral from the origins of each time epoch that reaches every lag of it (the
    // scatter the particles' subsets miss: a collective flux has few components).
    std::vector<double> by_epoch;
    for (int e = 0; e < kEpochs; ++e) {
      const auto epoch_at = [&](const Lag& lag) {
        return c(lag.epoch_mean[g][e], about_mean ? lag.epoch_mean_linear[g][e] : Vec<D>{});
      };
      double integral = 0.0;
      bool complete = true;
      for (std::size_t k = 1; complete && k < all.size() && all[k].lag <= to; ++k) {
        const double a = epoch_at(all[k]), b = epoch_at(all[k - 1]);
        complete = std::isfinite(a) && std::isfinite(b);
        integral += 0.5 * (all[k].lag - all[k - 1].lag) * (a + b);
      }
      if (complete) by_epoch.push_back(integral / D);
    }
    Diffusion d;
    d.lags = used_lags + 1;
    d.coefficient = total / D;
    std::vector<double> by_subset;
    for (int s = 0; s < kSubsets; ++s)
      if (group_size_[slot(g, s)] > 0) by_subset.push_back(part[s] / D);
    set_errors(d, by_subset, by_epoch);
    out[g] = d;
  }
  return out;
}

namespace {

// sum_g weight[g] value(g) over the weighted groups (NaN if one of them has no value).
template <class Value>
double combine(const std::vector<double>& weight, const Value& value) {
  double sum = 0.0;
  for (std::uint32_t g = 0; g < weight.size(); ++g)
    if (weight[g] != 0.0) sum += weight[g] * value(g);
  return sum;
}

}  // namespace

template <int D>
std::optional<typename MsdCorrelator<D>::Diffusion> MsdCorrelator<D>::combined_diffusion(
    double from, double to, const std::vector<double>& weight) const {
  if (weight.size() > groups_) throw std::invalid_argument("MsdCorrelator: too many weights");
  const std::vector<Lag> all = lags();
  std::vector<double> t, y;
  for (const Lag& lag : all) {
    if (lag.lag < from || lag.lag > to) continue;
    t.push_back(lag.lag);
    y.push_back(combine(weight, [&](std::uint32_t g) { return lag.mean[g]; }));
  }
  if (t.size() < 3) return std::nullopt;
  Diffusion d;
  d.lags = static_cast<int>(t.size());
  d.coefficient = slope(t, y) / (2.0 * D);
  std::vector<double> by_epoch;
  for (int e = 0; e < kEpochs; ++e) {
    std::vector<double> te, ye;
    for (const Lag& lag : all) {
      if (lag.lag < from || lag.lag > to) continue;
      const double value = combine(weight, [&](std::uint32_t g) { return lag.epoch_mean[g][e]; });
      if (std::isnan(value)) continue;
      te.push_back(lag.lag);
      ye.push_back(value);
    }
    if (te.size() >= 3) by_epoch.push_back(slope(te, ye) / (2.0 * D));
  }
  set_errors(d, {}, by_epoch);
  return d;
}

template <int D>
std::optional<typename MsdCorrelator<D>::Diffusion> MsdCorrelator<D>::combined_green_kubo(
    double to, const std::vector<double>& weight) const {
  if (weight.size() > groups_) throw std::invalid_argument("MsdCorrelator: too many weights");
  if (statistic_ == Statistic::kDisplacement) return std::nullopt;
  const std::vector<Lag> all = lags();
  if (all.empty() || all[0].lag != 0.0) return std::nullopt;
  const auto integral = [&](const auto& value_at) {
    double total = 0.0;
    int used = 0;
    for (std::size_t k = 1; k < all.size() && all[k].lag <= to; ++k, ++used)
      total += 0.5 * (all[k].lag - all[k - 1].lag) * (value_at(all[k]) + value_at(all[k - 1]));
    return std::pair{total, used};
  };
  const auto [total, used] = integral([&](const Lag& lag) {
    return combine(weight, [&](std::uint32_t g) { return lag.mean[g]; });
  });
  if (used < 2) return std::nullopt;
  std::vector<double> by_epoch;
  for (int e = 0; e < kEpochs; ++e) {
    const double value =
        integral([&](const Lag& lag) {
          return combine(weight, [&](std::uint32_t g) { return lag.epoch_mean[g][e]; });
        }).first;
    if (std::isfinite(value)) by_epoch.push_back(value / D);  // every lag of the epoch
  }
  Diffusion d;
  d.lags = used + 1;
  d.coefficient = total / D;
  set_errors(d, {}, by_epoch);
  return d;
}

template <int D>
std::uint64_t MsdCorrelator<D>::members(std::uint32_t g) const {
  std::uint64_t count = 0;
  for (int s = 0; s < kSubsets; ++s) count += group_size_[slot(g, s)];
  return count;
}

template <int D>
std::size_t MsdCorrelator<D>::bytes() const {
  std::size_t b = 0;
  for (const Level& l : levels_) {
    b +=
        l.ring.size() * sizeof(Vec<D>) +
        (l.sum2.size() + l.sum4.size() + l.sum1.size() + l.epoch_sum.size() + l.epoch_sum1.size()) *
            sizeof(double) +
        (l.count.size() + l.epoch_count.size()) * sizeof(std::uint64_t);
  }
  return b;
}

std::pair<double, double> correlation_fit_window(double sampled, double from, double to,
                                                 double mean_free_time, double to_mean_free_times) {
  if (!(to > 0.0)) {
    to = to_mean_free_times > 0.0 && std::isfinite(mean_free_time) && mean_free_time > 0.0
             ? to_mean_free_times * mean_free_time
             : 0.25 * sampled;
  }
  if (!(from > 0.0)) {
    from = std::max(0.1 * to, std::isfinite(mean_free_time) ? 10.0 * mean_free_time : 0.0);
  }
  return {from, to};
}

template class MsdCorrelator<1>;  // collective moments (run/outputs/transport_output.hpp)
template class MsdCorrelator<2>;
template class MsdCorrelator<3>;

}  // namespace kairos
