// to_toml: the effective configuration as config.toml writes it, each table's keys from their
// declarations (io/config_keys.hpp) in declaration order.
#include <fmt/format.h>
#include <fmt/ranges.h>

#include <array>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "io/config.hpp"
#include "io/config_keys.hpp"
#include "io/config_text.hpp"

namespace kairos {

using namespace config_detail;

std::string group_toml(const KeyGroup& group, const void* object, std::string_view prefix,
                       std::size_t dimension) {
  std::string out;
  for (const KeyDecl& d : group.keys) {
    const Field& f = d.member;
    if (!f || (d.written != nullptr && !d.written(object))) continue;
    std::string value;
    switch (f.cpp) {
      case CppType::kInt:
        value = fmt::format("{}", f.of<int>(object));
        break;
      case CppType::kInt64:
        value = fmt::format("{}", f.of<std::int64_t>(object));
        break;
      case CppType::kUint64:
        value = toml_unsigned(f.of<std::uint64_t>(object), join_key(prefix, d.name));
        break;
      case CppType::kDouble:
        value = toml_float(f.of<double>(object));
        break;
      case CppType::kBool:
        value = fmt::format("{}", f.of<bool>(object));
        break;
      case CppType::kString:
        value = toml_string(f.of<std::string>(object));
        break;
      case CppType::kDoubles: {
        const std::vector<double>& v = f.of<std::vector<double>>(object);
        value = toml_floats(
            d.type == KeyType::kVector && v.empty() ? std::vector<double>(dimension, d.fill) : v);
        break;
      }
      case CppType::kStrings: {
        const std::vector<std::string>& v = f.of<std::vector<std::string>>(object);
        std::vector<std::string> items;
        for (const std::string& item : v) items.push_back(toml_string(item));
        value = fmt::format("[{}]", fmt::join(items, ", "));
        break;
      }
      case CppType::kSpeedTable: {
        std::vector<std::string> items;
        for (const std::array<double, 2>& row : f.of<std::vector<std::array<double, 2>>>(object))
          items.push_back(fmt::format("[{}, {}]", toml_float(row[0]), toml_float(row[1])));
        value = fmt::format("[{}]", fmt::join(items, ", "));
        break;
      }
    }
    out += fmt::format("{} = {}\n", d.name, value);
  }
  return out;
}

namespace {

std::string species_pair_toml(const std::string& a, const std::string& b) {
  return fmt::format("species = [{}, {}]\n", toml_string(a), toml_string(b));
}

// The keys of a potential after its species or type, one per line.
std::string potential_toml(const PotentialSpec& p, std::string_view prefix) {
  std::string out = fmt::format("kind = {}\n", toml_string(p.kind));
  out += group_toml(potential_keys(), &p, prefix, 3);
  out += group_toml(spring_dashpot_keys(), &p, prefix, 3);
  return out;
}

}  // namespace

std::string default_lattice(int dimension) {
  if (dimension == 2) return "hex";
  if (dimension == 3) return "fcc";
  throw std::invalid_argument(
      fmt::format("default_lattice: dimension must be 2 or 3, got {}", dimension));
}

std::string to_toml(const Config& config) {
  SystemConfig s = config.system;
  if (s.lattice.empty() && (s.dimension == 2 || s.dimension == 3)) {
    s.lattice = default_lattice(s.dimension);
  }
  if (s.species.empty()) s.species.emplace_back();
  // Vectors left empty (the defaults) are written with their effective values.
  const std::size_t dimension = s.dimension == 2 ? 2 : 3;
  const auto table = [&](std::string_view name, const KeyGroup& group, const void* object) {
    return fmt::format("\n[{}]\n{}", name, group_toml(group, object, name, dimension));
  };

  std::string out;
  out += "# Kairos run configuration: the effective value of every key (see docs/config.md).\n";
  out += table("system", system_keys(), &s);
  for (const SpeciesConfig& sp : s.species) {
    out += "\n[[system.species]]\n";
    out += group_toml(species_keys(), &sp, "system.species", dimension);
  }
  for (const PairPotentialConfig& pc : config.potentials) {
    out += "\n[[potential]]\n";
    if (!pc.species.empty()) out += species_pair_toml(pc.species[0], pc.species[1]);
    out += potential_toml(pc.potential, "potential");
  }
  for (const BondConfig& bc : config.bonds) {
    out += "\n[[bond]]\n";
    out += fmt::format("type = {}\n", toml_string(bc.type));
    out += potential_toml(bc.potential, "bond");
  }
  const InteractionConfig& in = config.interactions;
  out += table("contact", contact_law_keys(), &in.contact);
  out += group_toml(contact_keys(), &in, "contact", dimension);
  for (const PairContactConfig& pair : in.pairs) {
    out += "\n[[contact.pair]]\n";
    out += species_pair_toml(pair.species[0], pair.species[1]);
    out += group_toml(contact_law_keys(), &pair.contact, "contact.pair", dimension);
  }
  out += table("boundary", boundary_keys(), &config.boundary);
  for (const WallConfig& w : config.boundary.walls) {
    out += "\n[[boundary.wall]]\n";
    out += fmt::format("face = {}\n", toml_string(w.face));
    out += group_toml(contact_law_keys(), &w.contact, "boundary.wall", dimension);
    out += group_toml(wall_keys(), &w, "boundary.wall", dimension);
  }
  if (!config.boundary.container.axis.empty()) {
    out += "\n[boundary.container]\n";
    out +=
        group_toml(container_keys(), &config.boundary.container, "boundary.container", dimension);
  }
  if (!config.boundary.outlet.normal.empty()) {
    out += "\n[boundary.outlet]\n";
    out += group_toml(outlet_keys(), &config.boundary.outlet, "boundary.outlet", dimension);
  }
  // The surface tables after the outlet, in the order of SurfaceTables (as docs/config.md).
  for_each_surface_table(config.boundary.surfaces, [&](auto surface, const auto& entries) {
    for (const auto& entry : entries)
      out += fmt::format("\n[[boundary.{}]]\n{}", surface.key, surface.toml(entry, dimension));
  });
  out += table("driving", driving_keys(), &config.driving);
  out += table("field", field_keys(), &config.field);
  const SoftConfig& soft = config.soft;
  if (soft.enabled()) {
    out += table("soft", soft_law_keys(), &soft.law);
    out += group_toml(soft_keys(), &soft, "soft", dimension);
    for (const SoftPairConfig& pair : soft.pairs) {
      out += "\n[[soft.pair]]\n";
      out += species_pair_toml(pair.species[0], pair.species[1]);
      out += group_toml(soft_law_keys(), &pair.law, "soft.pair", dimension);
    }
  }
  // Each phase's length in its one unit (both would be refused when the file is read back), and
  // interval_unit unless "" (a config built in code: the reader's default).
  out += table("run", run_keys(), &config.run);
  out += table("output", output_keys(), &config.output);
  // Only when some key differs from its default: a run without analyses writes the file it
  // wrote before [analysis] existed.
  if (config.analysis != AnalysisConfig{})
    out += table("analysis", analysis_keys(), &config.analysis);
  if (config.compress != CompressConfig{})
    out += table("compress", compress_keys(), &config.compress);
  return out;
}

}  // namespace kairos
