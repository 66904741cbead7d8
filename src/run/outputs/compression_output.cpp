#include "run/outputs/compression_output.hpp"

#include <cmath>

#include <fmt/format.h>

#include "io/atomic_file.hpp"
#include "io/gsd_file.hpp"
#include "io/gsd_snapshot.hpp"
#include "run/outputs/summary_values.hpp"

namespace kairos {

template <int D>
void CompressionOutput<D>::open(const RunContext<D>& run) {
  const CompressionResult& r = report_->result;
  std::string rows =
      "# time\tpacking_fraction\treduced_pressure\tkT_before_rescaling\tcollisions\t"
      "collision_rate\n";
  for (const CompressionRow& row : r.rows) {
    rows += fmt::format("{:.17g}\t{:.17g}\t{:.10g}\t{:.10g}\t{}\t{:.10g}\n", row.time,
                        row.packing_fraction, row.pressure, row.temperature, row.collisions,
                        row.collision_rate);
  }
  write_text_atomically(run.directory() / kRowsFile, rows);

  const ContactNetwork& net = report_->network;
  if (!report_->has_network) {
    write_text_atomically(run.directory() / kContactsFile,
                          "# no contact network: the packing is not near jamming (reduced pressure "
                          "below 1e6) and compress.contact_gap is 0\n");
  }
  std::string contacts = fmt::format(
      "# contacts of the packing in packing.gsd: relative gap (r - sigma_ij) / sigma_ij below "
      "{:.3g}; "
      "rattler_i/j: 1 for a rattler (docs/outputs.md)\n# i\tj\tgap\trattler_i\trattler_j\n",
      net.gap_tolerance);
  for (const Contact& c : net.contacts) {
    contacts += fmt::format("{}\t{}\t{:.6g}\t{}\t{}\n", c.i, c.j, c.gap, int{net.rattler[c.i]},
                            int{net.rattler[c.j]});
  }
  // A wall contact names the wall's face as j (x-, ..., z+), its gap relative to the diameter.
  for (const WallContact& c : net.wall_contacts) {
    contacts += fmt::format("{}\t{}{}\t{:.6g}\t{}\t0\n", c.i, "xyz"[c.face / 2],
                            c.face % 2 == 0 ? '-' : '+', c.gap, int{net.rattler[c.i]});
  }
  if (report_->has_network) write_text_atomically(run.directory() / kContactsFile, contacts);

  TrajectoryLayout layout;
  layout.double_precision = true;
  replace_file_atomically(run.directory() / kPackingFile, [&](const std::filesystem::path& tmp) {
    auto w = gsd::Writer::create(tmp, "kairos " KAIROS_VERSION);
    append_trajectory_frame(w, *packing_, layout);
    w.close();
  });
}

void summarize_compression(const CompressionReport& report, int dimension,
                           nlohmann::json& summary) {
  const CompressionResult& r = report.result;
  const CompressionSettings& s = report.settings;
  const ContactNetwork& net = report.network;
  const int D = dimension;
  nlohmann::json& c = summary["compression"];
  c["stop_reason"] = r.stop_reason;
  c["initial_packing_fraction"] = r.initial_packing_fraction;
  c["packing_fraction"] = r.packing_fraction;
  set_or_explain(summary, c, "reduced_pressure", r.pressure,
                 r.rows.empty() ? "no thermostat interval ended during the compression" : "",
                 "compression.reduced_pressure");
  set_or_explain(summary, c, "collision_rate", r.collision_rate,
                 r.rows.empty() ? "no thermostat interval ended during the compression" : "",
                 "compression.collision_rate");
  // The free-volume law p = D / (1 - phi / phi_J) (Salsburg and Wood 1962) read backwards:
  // the jamming density the pressure points at (docs/physics.md#jammed-packings).
  const double phi_j = r.packing_fraction / (1.0 - D / r.pressure);
  set_or_explain(summary, c, "free_volume_jamming_density", phi_j,
                 r.pressure > 100.0 ? "" : "the reduced pressure is below 100: far from jamming",
                 "compression.free_volume_jamming_density");
  c["growth_rate"] = s.growth_rate;
  c["thermostat_interval"] = s.thermostat_interval;
  c["time"] = r.time;
  c["collisions"] = r.collisions;
  c["rescalings"] = r.rescalings;
  c["rebuilds"] = r.rebuilds;
  c["diameter_scale"] = r.diameter_scale;
  c["wall_seconds"] = report.wall_seconds;
  nlohmann::json& order = c["bond_order"];
  order["cutoff"] = CompressionReport::kBondCutoff;
  for (std::size_t k = 0; k < report.order_names.size(); ++k) {
    set_or_explain(summary, order, report.order_names[k], report.order[k],
                   std::isfinite(report.order[k]) ? "" : "no particle has a neighbour",
                   "compression.bond_order." + report.order_names[k]);
  }
  if (!report.has_network) {
    c["contacts"] = nullptr;
    summary["undefined"]["compression.contacts"] =
        "the packing is not near jamming (reduced pressure below 1e6): touching and open pairs "
        "are not told apart by their gaps (compress.contact_gap sets a tolerance)";
    return;
  }
  nlohmann::json& k = c["contacts"];
  k["gap_tolerance"] = net.gap_tolerance;
  k["contacts"] = net.contacts.size();
  k["wall_contacts"] = net.wall_contacts.size();
  k["coordination"] = net.coordination;
  k["rattlers"] = net.rattlers;
  k["rattler_fraction"] = net.rattler_fraction;
  k["backbone_contacts"] = net.backbone_contacts;
  k["backbone_wall_contacts"] = net.backbone_wall_contacts;
  k["backbone_coordination"] = net.backbone_coordination;
  k["isostatic_excess"] = net.excess_contacts;
  k["largest_contact_gap"] = net.largest_contact_gap;
  set_or_explain(summary, k, "smallest_open_gap", net.smallest_open_gap,
                 std::isfinite(net.smallest_open_gap) ? "" : "no open pair within 1.1 sigma",
                 "compression.contacts.smallest_open_gap");
}

template <int D>
void CompressionOutput<D>::summarize(nlohmann::json& summary, const RunContext<D>&) const {
  summarize_compression(*report_, D, summary);
}

template class CompressionOutput<2>;
template class CompressionOutput<3>;

}  // namespace kairos
