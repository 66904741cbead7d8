#include "run/outputs/rdf_output.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <fmt/format.h>

#include "core/error.hpp"
#include "io/atomic_file.hpp"
#include "run/event_adapter.hpp"
#include "run/outputs/summary_values.hpp"

namespace kairos {

template <int D>
RdfPairs rdf_pairs(const Integrator<D>& integrator, const StructureSnapshot<D>& snapshot) {
  const std::vector<std::string>& names = snapshot.species_names();
  const std::size_t species = names.size();
  RdfPairs out;
  // Contact values need hard cores (no soft spheres, no steps at or near them) and one radius
  // per species.
  const EventIntegrator<D>* engine = integrator.as_event();
  if (engine == nullptr || engine->soft())
    out.no_contact = "soft spheres: no contact value";
  else if (engine->stepped())
    out.no_contact = "stepped potentials: steps near the hard core";
  out.contact.assign(species_pairs(species), std::numeric_limits<double>::quiet_NaN());
  out.names.assign(species_pairs(species), "");
  for (std::size_t a = 0; a < species; ++a) {
    for (std::size_t b = a; b < species; ++b) {
      const std::size_t p = species_pair_index(a, b, species);
      out.names[p] = names[a] + "-" + names[b];
      const double sigma = snapshot.species_radius()[a] + snapshot.species_radius()[b];
      const bool present = snapshot.counts()[a] > 0 && snapshot.counts()[b] > 0;
      if (out.no_contact.empty() && present) {
        if (std::isnan(sigma)) out.no_contact = "the radii of a species differ";
        out.contact[p] = sigma;
      }
    }
  }
  if (!out.no_contact.empty()) std::fill(out.contact.begin(), out.contact.end(), std::nan(""));
  return out;
}

template <int D>
double automatic_rdf_distance(const StructureSnapshot<D>& snapshot, const Configuration<D>& c) {
  const double shortest = *std::min_element(c.box.begin(), c.box.end());
  return std::min(10.0 * snapshot.largest_radius(), 0.5 * shortest);
}

template <int D>
void RdfOutput<D>::begin(const RunContext<D>& run) {
  const Integrator<D>& integrator = run.integrator();
  const Configuration<D>& c = snapshot_->at(integrator);
  const EventIntegrator<D>* engine = integrator.as_event();
  RdfPairs pairs = rdf_pairs(integrator, *snapshot_);
  pair_names_ = std::move(pairs.names);
  no_contact_ = std::move(pairs.no_contact);
  const std::vector<double>& contact = pairs.contact;
  // The contact theorem: an elastic, smooth, unforced gas in a periodic box.
  if (!no_contact_.empty()) {
    no_theorem_ = no_contact_;
  } else if (!integrator.bulk()) {
    no_theorem_ = not_bulk_reason(integrator.mobile() < integrator.size(), true);
  } else if (engine->kind().dissipative || engine->kind().rotating) {
    no_theorem_ = "inelastic or rough collisions: the contact theorem holds for elastic spheres";
  } else if (engine->kind().sheared || engine->kind().driven) {
    no_theorem_ = "a driven or sheared gas: not in equilibrium";
  }
  double max_distance = run.config().analysis.rdf_max_distance;
  const double shortest = *std::min_element(c.box.begin(), c.box.end());
  if (max_distance == 0.0) max_distance = automatic_rdf_distance(*snapshot_, c);
  try {
    rdf_.emplace(c.box, c.periodic, snapshot_->counts(), max_distance,
                 static_cast<int>(run.config().analysis.rdf_bins), contact);
  } catch (const std::invalid_argument&) {
    throw InputError(fmt::format(
        "analysis.rdf: the box (shortest edge {:.6g}) is too small for g(r) up to {:.6g} and the "
        "contact windows (1.1 contact distances): both must stay within half of every edge",
        shortest, max_distance));
  }
}

template <int D>
void RdfOutput<D>::finish(const RunContext<D>& run) {
  const PairCorrelation<D>& g = *rdf_;
  const std::size_t pairs = pair_names_.size();
  const bool total = pairs > 1;
  std::string text = fmt::format(
      "# {} samples; r: the bin's centre (bins of {:.10g}); g_X-Y: g(r) of the species pair X-Y"
      "{}, each with its standard error (blocking over the samples)\n",
      g.samples(), g.bin_width(), total ? ", g_all: of every pair" : "");
  for (std::size_t p = 0; p < pairs; ++p) {
    const BlockAverage c = g.contact(p);
    if (c.samples > 0) {
      text += fmt::format("# contact {}: sigma = {:.10g}, g(sigma+) = {:.10g} +- {:.3g}\n",
                          pair_names_[p], g.contact_distance(p), c.mean, c.stderr_);
    }
  }
  text += "r";
  for (const std::string& name : pair_names_) text += fmt::format("\tg_{0}\tg_{0}_stderr", name);
  if (total) text += "\tg_all\tg_all_stderr";
  text += "\n";
  for (int k = 0; k < g.bins(); ++k) {
    text += fmt::format("{:.10g}", (k + 0.5) * g.bin_width());
    for (std::size_t p = 0; p < pairs; ++p) {
      const BlockAverage v = g.g(p, k);
      if (v.samples == 0) {
        text += "\tnan\tnan";  // a species pair without pairs (a species of one particle)
      } else {
        text += fmt::format("\t{:.10g}\t{:.4g}", v.mean, v.stderr_);
      }
    }
    if (total) {
      const BlockAverage v = g.g_all(k);
      text += fmt::format("\t{:.10g}\t{:.4g}", v.mean, v.stderr_);
    }
    text += "\n";
  }
  write_text_atomically(run.directory() / name(), text);
}

template <int D>
void RdfOutput<D>::summarize(nlohmann::json& summary, const RunContext<D>& run) const {
  nlohmann::json* part = this->part(summary, "rdf", run);
  if (part == nullptr || !rdf_) return;
  nlohmann::json& j = *part;
  const PairCorrelation<D>& g = *rdf_;
  j["max_distance"] = g.max_distance();
  j["bins"] = g.bins();
  const std::string few = g.samples() < 2 ? "fewer than 2 samples" : "";
  if (!no_contact_.empty()) {
    summary["undefined"]["analysis.rdf.contact"] = no_contact_;
    j["contact"] = nullptr;
  } else {
    j["contact_method"] = fmt::format(
        "cubic least-squares fit of {} bins over sigma <= r < {} sigma, evaluated at sigma",
        PairCorrelation<D>::kContactBins, 1.0 + PairCorrelation<D>::kContactWindow);
    nlohmann::json& contact = j["contact"];
    for (std::size_t p = 0; p < pair_names_.size(); ++p) {
      const BlockAverage c = g.contact(p);
      nlohmann::json entry;
      const std::string name = "analysis.rdf.contact." + pair_names_[p];
      const std::string none = c.samples == 0 ? "no pair of this species pair" : "";
      set_or_explain(summary, entry, "sigma", g.contact_distance(p), none, name + ".sigma");
      set_or_explain(summary, entry, "g", c.mean, none, name + ".g");
      set_or_explain(summary, entry, "stderr", c.stderr_, none.empty() ? few : none,
                     name + ".stderr");
      if (none.empty()) set_error_quality(entry, "stderr", c);
      contact[pair_names_[p]] = entry;
    }
    j["overlapping_pairs_last_sample"] = g.overlapping();
    j["pairs_at_contact_last_sample"] = g.at_contact();
  }
  const BlockAverage z = g.contact_compressibility();
  const std::string why = !no_theorem_.empty() ? no_theorem_
                          : z.samples == 0     ? "a species pair without pairs"
                                               : "";
  nlohmann::json from_contact;
  set_or_explain(summary, from_contact, "mean", z.mean, why,
                 "analysis.rdf.compressibility_from_contact.mean");
  set_or_explain(summary, from_contact, "stderr", z.stderr_, why.empty() ? few : why,
                 "analysis.rdf.compressibility_from_contact.stderr");
  if (why.empty()) set_error_quality(from_contact, "stderr", z);
  j["compressibility_from_contact"] = from_contact;
  if (!why.empty()) return;
  // Z measured by the collision virial over the same production (summary.json's
  // `compressibility`), beside it.
  const BlockAverage measured = thermo_.production_compressibility(run.integrator());
  nlohmann::json virial;
  set_or_explain(summary, virial, "mean", measured.mean, "",
                 "analysis.rdf.compressibility_virial.mean");
  set_or_explain(summary, virial, "stderr", measured.stderr_,
                 measured.samples < 2 ? "fewer than 2 production thermo rows" : "",
                 "analysis.rdf.compressibility_virial.stderr");
  j["compressibility_virial"] = virial;
  const double combined = std::hypot(z.stderr_, measured.stderr_);
  set_or_explain(summary, j, "compressibility_difference_in_stderr",
                 (z.mean - measured.mean) / combined, combined > 0.0 ? "" : "no error estimate",
                 "analysis.rdf.compressibility_difference_in_stderr");
}

template RdfPairs rdf_pairs<2>(const Integrator<2>&, const StructureSnapshot<2>&);
template RdfPairs rdf_pairs<3>(const Integrator<3>&, const StructureSnapshot<3>&);
template double automatic_rdf_distance<2>(const StructureSnapshot<2>&, const Configuration<2>&);
template double automatic_rdf_distance<3>(const StructureSnapshot<3>&, const Configuration<3>&);
template class RdfOutput<2>;
template class RdfOutput<3>;

}  // namespace kairos
