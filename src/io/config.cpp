// Run configuration: reading and validation (the overrides: io/config_override.cpp; the
// writing: io/config_writer.cpp; the text of messages: io/config_text.cpp).
//
// The declarations of io/config_keys.hpp drive the unknown-key checks, the "did you mean"
// suggestions, the override coercions, the typed reading and range checks of every key with a
// member, and the writing; the rules between keys are spelled out per section below. Every error is
// an InputError with a one-line message "WHERE: KEY: PROBLEM", WHERE being "file:line:column",
// "file" or "override 'key=value'".
#include "io/config.hpp"
#include "io/config_obstacles.hpp"

#include "boundaries/wall_spring.hpp"

#include "interactions/parameter_domain.hpp"

#include <fmt/format.h>

#include <toml++/toml.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <initializer_list>
#include <limits>
#include <memory>
#include <numbers>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <system_error>
#include <utility>
#include <vector>

#include "core/error.hpp"
#include "io/config_choices.hpp"
#include "io/config_key_reader.hpp"
#include "io/config_keys.hpp"
#include "io/config_override.hpp"
#include "io/config_text.hpp"

namespace kairos {
namespace {

using namespace config_detail;

constexpr std::uint64_t kMaxParticles = (std::uint64_t{1} << 31) - 1;

// The name of face number f (2k: the low face of axis k, 2k + 1 the high one), and of axis k.
std::string_view face_name(std::size_t f) {
  return box_faces().entries()[f].name;
}
std::string_view axis_name(std::size_t k) {
  return axes().entries()[k].name;
}

// ---------------------------------------------------------------------------------------------
// Reading and validation

class Reader : public KeyReader {
 public:
  using KeyReader::KeyReader;

  Config read(const toml::table& root) const {
    check_keys(root, "");
    const toml::table empty;
    Config config;
    read_system(section(root, "system", empty), config.system);
    read_interactions(section(root, "contact", empty), config.system.species, config.interactions);
    read_boundary(section(root, "boundary", empty), config.system.dimension,
                  config.interactions.contact, config.boundary);
    read_field(section(root, "field", empty), config.system.dimension, config.field);
    read_driving(section(root, "driving", empty), config.driving);
    read_run(section(root, "run", empty), config.run);
    read_output(section(root, "output", empty), config.system.dimension, config.output);
    resolve_interval_unit(section(root, "output", empty), config.run, config.output);
    read_group(section(root, "analysis", empty), "analysis", analysis_keys(), &config.analysis,
               nullptr);
    read_group(section(root, "compress", empty), "compress", compress_keys(), &config.compress,
               nullptr);
    read_potentials(root, config.system.species, config.potentials);
    read_bonds(root, config.bonds);
    if (root.contains("soft")) {
      read_soft(section(root, "soft", empty), config.system.species, config.soft);
    }
    check_soft_and_dem(root, config);
    check_fixed_species(root, config);
    check_wall_masses(root, config);
    check_container(root, config);
    check_outlet(root, config);
    check_compress(root, config);
    check_trajectory_keys(root, config);
    if (config.system.chain_length > 0 && config.bonds.empty()) {
      fail(nullptr, "system.chain_length",
           "system.chain_length: chains need a bond potential ([[bond]] with kind = \"tether\" "
           "or \"spring\")");
    }
    resolve_chain_spacing(config);
    return config;
  }

 private:
  // system.chain_spacing = 0: halfway between the contact distance and the backbone bond's
  // range, so that bonded beads start apart (at a spacing of one diameter they start exactly in
  // contact, and a short run makes all its collisions at t = 0: its clock never moves).
  static void resolve_chain_spacing(Config& config) {
    SystemConfig& s = config.system;
    if (s.chain_length == 0 || s.chain_spacing != 0.0) return;
    double dmax = 0.0;
    for (const SpeciesConfig& sp : s.species) dmax = std::max(dmax, sp.diameter);
    for (const BondConfig& b : config.bonds) {
      if (b.type != "backbone") continue;
      const double range = table_cutoff(b.potential, dmax);
      if (std::isfinite(range) && range > dmax) s.chain_spacing = 0.5 * (dmax + range);
    }
  }

  // ----- sections

  // system.size_distribution and system.polydispersity: both or neither, within the range the
  // distribution keeps positive diameters in.
  void check_size_distribution(const toml::table& t, const SystemConfig& s) const {
    const SizeDistribution kind = size_distributions().at(s.size_distribution);
    const toml::node* n = t.get("polydispersity");
    if (kind == SizeDistribution::kNone) {
      if (s.polydispersity != 0.0)
        fail(n, "system.polydispersity",
             "system.polydispersity: set system.size_distribution (uniform, gaussian or "
             "lognormal) for it to act");
      return;
    }
    const double limit = kind == SizeDistribution::kUniform    ? 1.0 / std::sqrt(3.0)
                         : kind == SizeDistribution::kGaussian ? 0.3
                                                               : 1.0;
    if (!(s.polydispersity > 0.0) || !(s.polydispersity < limit)) {
      fail(n != nullptr ? n : t.get("size_distribution"), "system.polydispersity",
           fmt::format("system.polydispersity = {} is outside (0, {:.4g}) for "
                       "size_distribution = \"{}\"{}",
                       s.polydispersity, limit, s.size_distribution,
                       kind == SizeDistribution::kUniform
                           ? " (the smallest diameter would not be positive)"
                       : kind == SizeDistribution::kGaussian
                           ? " (a wider normal would be cut much at 0 and 2 d)"
                           : ""));
    }
    if (s.chain_length > 0)
      fail(n, "system.size_distribution",
           "system.size_distribution: chains are built of equal beads");
  }

  void read_system(const toml::table& t, SystemConfig& s) const {
    read_group(t, "system", system_keys(), &s, &s.dimension);
    const toml::node* n_particles = t.get("particles");
    const toml::node* n_packing = t.get("packing_fraction");
    const toml::node* n_lattice = t.get("lattice");
    const toml::node* n_chain = t.get("chain_length");
    const toml::node* n_spacing = t.get("chain_spacing");
    if (s.chain_length == 1) {
      fail(n_chain, "system.chain_length",
           "system.chain_length: a chain needs at least 2 beads (0: no chains)");
    }
    read_species(t, s.species);
    check_size_distribution(t, s);

    const bool from_file = !s.initial_state.empty();
    if (!from_file) {
      if (n_particles == nullptr) {
        fail(nullptr, "system.particles",
             "missing required key 'system.particles' (or set system.initial_state to start from "
             "a GSD file)");
      }
      if (n_packing == nullptr) {
        fail(nullptr, "system.packing_fraction",
             "missing required key 'system.packing_fraction' (or set system.initial_state to "
             "start from a GSD file)");
      }
    }
    // With an initial_state, 0 (the default) leaves particles and packing fraction to the file.
    if (!(from_file && s.particles == 0) && s.particles < 2) {
      fail(n_particles, "system.particles",
           fmt::format("system.particles: must be at least 2, got {}", s.particles));
    }
    // The engine numbers particles in 31 bits (docs/architecture.md).
    if (s.particles > kMaxParticles) {
      fail(n_particles, "system.particles",
           fmt::format("system.particles: must be at most {} (2^31 - 1), got {}", kMaxParticles,
                       s.particles));
    }
    // Whether the state fits in memory is checked before it is built (core/memory_budget).
    if (!(from_file && s.packing_fraction == 0.0) &&
        !(s.packing_fraction > 0.0 && s.packing_fraction < 1.0)) {
      fail(n_packing, "system.packing_fraction",
           fmt::format("system.packing_fraction: must be in (0, 1), got {}", s.packing_fraction));
    }
    // More dilute, and neighbours sit more than ~1e3 diameters apart: the box outgrows what
    // positions resolve before the gas is any different from one at 1e-9.
    if (!(from_file && s.packing_fraction == 0.0) && s.packing_fraction < 1e-9) {
      fail(n_packing, "system.packing_fraction",
           fmt::format("system.packing_fraction: must be at least 1e-9, got {}",
                       s.packing_fraction));
    }
    if (s.chain_length > 0 && s.particles > 0 && s.chain_length > s.particles) {
      fail(n_chain, "system.chain_length",
           fmt::format("system.chain_length: must be at most system.particles = {}, got {}",
                       s.particles, s.chain_length));
    }

    if (s.lattice.empty()) {
      s.lattice = default_lattice(s.dimension);
    } else if (!lattices(s.dimension).contains(s.lattice)) {
      fail(n_lattice, "system.lattice",
           fmt::format("system.lattice: '{}' is not a valid lattice in {}D; valid values: {}",
                       shown(s.lattice), s.dimension, lattices(s.dimension).names()));
    }

    if (s.species.empty()) s.species.emplace_back();
    double largest = 0.0;
    for (const SpeciesConfig& sp : s.species) largest = std::max(largest, sp.diameter);
    if (s.chain_spacing > 0.0 && !(s.chain_spacing <= 1e6 * largest)) {
      fail(n_spacing, "system.chain_spacing",
           fmt::format("system.chain_spacing: must be in [0, {:g}] (0, or up to 1e6 times the "
                       "largest diameter), got {}",
                       1e6 * largest, s.chain_spacing));
    }
  }

  void read_species(const toml::table& system, std::vector<SpeciesConfig>& out) const {
    const std::vector<const toml::table*> tables = table_array(system, "system", "species");
    for (std::size_t i = 0; i < tables.size(); ++i) {
      const toml::table* t = tables[i];
      const toml::node* element = t;
      const std::string prefix = fmt::format("system.species[{}]", i);

      SpeciesConfig s;
      read_group(*t, prefix, species_keys(), &s, nullptr);
      const toml::node* n_name = t->get("name");
      const std::string name_key = prefix + ".name";
      if (s.name.empty()) fail(n_name, name_key, fmt::format("{}: must not be empty", name_key));
      for (std::size_t j = 0; j < out.size(); ++j) {
        if (out[j].name == s.name) {
          fail(n_name != nullptr ? n_name : element, n_name != nullptr ? name_key : prefix,
               fmt::format("{}: duplicate species name '{}' (already used by system.species[{}]){}",
                           name_key, s.name, j,
                           n_name == nullptr ? "; give every species its own name" : ""));
        }
      }
      out.push_back(std::move(s));
    }
  }

  // A contact law at `prefix` ("contact", "contact.pair[i]", "boundary.wall[i]"). On entry `c`
  // holds the law inherited from [contact] (the defaults for [contact] itself); the keys present
  // replace its values.
  void read_contact(const toml::table& t, const std::string& prefix, ContactConfig& c) const {
    const auto path = [&](std::string_view key) { return join_key(prefix, key); };
    read_group(t, prefix, contact_law_keys(), &c, nullptr);
    const toml::node* n_restitution = t.get("restitution");
    const toml::node* n_model = t.get("restitution_model");
    const toml::node* n_table = t.get("restitution_table");
    if (restitution_models().is(c.restitution_model, RestitutionModel::kViscoelastic) &&
        !kSoftRestitutionDomain.contains(c.restitution)) {
      fail(n_restitution != nullptr ? n_restitution : n_model, path("restitution"),
           fmt::format("{}: must be {} with restitution_model = \"viscoelastic\" (it is "
                       "e at restitution_speed), got {}",
                       path("restitution"), kSoftRestitutionDomain.text(), c.restitution));
    }
    if (restitution_models().is(c.restitution_model, RestitutionModel::kTable)) {
      if (n_table == nullptr && c.restitution_table.empty()) {
        fail(n_model, path("restitution_table"),
             fmt::format("missing required key '{}' (restitution_model = \"table\" needs "
                         "[speed, e] pairs, e.g. [[0.0, 1.0], [1.0, 0.9]])",
                         path("restitution_table")));
      }
      if (c.restitution_table.empty()) {
        fail(n_table, path("restitution_table"),
             fmt::format("{}: needs at least one [speed, e] pair", path("restitution_table")));
      }
    } else if (n_table != nullptr) {
      fail(n_table, path("restitution_table"),
           fmt::format("{}: only allowed with restitution_model = \"table\" (restitution_model "
                       "is \"{}\")",
                       path("restitution_table"), c.restitution_model));
    } else {
      c.restitution_table.clear();  // an inherited table does not apply to another model
    }
  }

  void read_interactions(const toml::table& t, const std::vector<SpeciesConfig>& species,
                         InteractionConfig& in) const {
    constexpr std::string_view p = "contact";
    read_contact(t, std::string(p), in.contact);
    read_group(t, std::string(p), contact_keys(), &in, nullptr);

    const std::vector<const toml::table*> tables = table_array(t, p, "pair");
    for (std::size_t i = 0; i < tables.size(); ++i) {
      const std::string prefix = fmt::format("contact.pair[{}]", i);
      std::vector<std::array<std::string, 2>> given;
      for (const PairContactConfig& other : in.pairs) given.push_back(other.species);
      PairContactConfig pair;
      pair.species = read_species_pair(*tables[i], prefix, "contact.pair", species, given);
      pair.contact = in.contact;
      read_contact(*tables[i], prefix, pair.contact);
      in.pairs.push_back(std::move(pair));
    }
  }

  // The `species` key of a [[contact.pair]] / [[soft.pair]] table at `prefix`: two declared
  // species names, a pair not already among `given` (the earlier tables of `list`).
  std::array<std::string, 2> read_species_pair(
      const toml::table& t, const std::string& prefix, std::string_view list,
      const std::vector<SpeciesConfig>& species,
      const std::vector<std::array<std::string, 2>>& given) const {
    const std::string species_key = prefix + ".species";
    std::vector<std::string> names;
    const toml::node* n_species = get_strings(t, prefix, "species", names);
    if (n_species == nullptr) {
      fail(&t, species_key,
           fmt::format("missing required key '{}' (the pair's two species, e.g. species = "
                       "[\"A\", \"B\"])",
                       species_key));
    }
    if (names.size() != 2) {
      fail(n_species, species_key,
           fmt::format("{}: expected 2 species names, got {}", species_key, names.size()));
    }
    for (std::size_t k = 0; k < 2; ++k) {
      const bool declared = std::any_of(species.begin(), species.end(),
                                        [&](const SpeciesConfig& s) { return s.name == names[k]; });
      if (!declared) {
        std::vector<std::string_view> known;
        for (const SpeciesConfig& s : species) known.push_back(s.name);
        fail(element_of(n_species, k), species_key,
             fmt::format("{}: unknown species '{}' (declared species: {})", species_key, names[k],
                         join_words(known)));
      }
    }
    for (std::size_t j = 0; j < given.size(); ++j) {
      const auto& other = given[j];
      if ((other[0] == names[0] && other[1] == names[1]) ||
          (other[0] == names[1] && other[1] == names[0])) {
        fail(n_species, species_key,
             fmt::format("{}: the pair ({}, {}) is already given by {}[{}]", species_key, names[0],
                         names[1], list, j));
      }
    }
    return {names[0], names[1]};
  }

  // The number (face_number()) of a face name valid in `dimension`.
  int face_index(const toml::node* node, const std::string& path, const std::string& face,
                 int dimension) const {
    const Choices<BoxFace>& valid = box_faces(dimension);
    if (!valid.contains(face)) {
      const bool other_dimension = box_faces().contains(face);
      fail(node, path,
           fmt::format("{}: '{}' is not {}; valid values: {}", path, face,
                       other_dimension ? fmt::format("a face of a {}D box", dimension)
                                       : std::string("a valid face"),
                       valid.names()));
    }
    return face_number(valid.at(face));
  }

  // One entry of a surface table (io/surface_table.hpp) as the table's rules see it: its
  // table, path and dimension, and [contact]'s law that its own contact law starts from.
  class EntryReading final : public TableReading {
   public:
    EntryReading(const Reader& reader, const toml::table& table, std::string prefix, int dimension,
                 const ContactConfig& contact)
        : reader_(reader),
          table_(table),
          prefix_(std::move(prefix)),
          dimension_(dimension),
          contact_(contact) {}
    const std::string& prefix() const override { return prefix_; }
    int dimension() const override { return dimension_; }
    bool has(std::string_view key) const override { return table_.get(key) != nullptr; }
    [[noreturn]] void fail(std::string_view key, const std::string& message) const override {
      const toml::node* node = key.empty() ? nullptr : table_.get(key);
      reader_.fail(node != nullptr ? node : &table_,
                   key.empty() ? prefix_ : prefix_ + "." + std::string(key), message);
    }
    void read_group(const KeyGroup& group, void* object) const override {
      reader_.read_group(table_, prefix_, group, object, &dimension_);
    }
    void read_contact(ContactConfig& law) const override {
      law = contact_;
      reader_.read_contact(table_, prefix_, law);
    }
    void require_vectors(std::initializer_list<const char*> keys) const override {
      reader_.require_vectors(table_, prefix_, keys, dimension_);
    }
    void require_nonzero(const char* key, const std::vector<double>& v,
                         std::string_view meaning) const override {
      reader_.require_nonzero(table_, prefix_, key, v, meaning);
    }

   private:
    const Reader& reader_;
    const toml::table& table_;
    std::string prefix_;
    int dimension_;
    const ContactConfig& contact_;
  };

  // Vector keys a table must have (a plane's normal and point, an outlet's region): an error
  // naming the first one missing.
  void require_vectors(const toml::table& t, const std::string& prefix,
                       std::initializer_list<const char*> keys, int dimension) const {
    for (const char* key : keys) {
      if (t.get(key) == nullptr) {
        fail(&t, prefix + "." + key,
             fmt::format("missing required key '{}.{}' ({} numbers)", prefix, key, dimension));
      }
    }
  }

  // A direction that must not be the zero vector (a normal, normalised later); `meaning` says
  // which way it points.
  void require_nonzero(const toml::table& t, const std::string& prefix, const char* key,
                       const std::vector<double>& v, std::string_view meaning) const {
    double n2 = 0.0;
    for (const double c : v) n2 += c * c;
    if (!(n2 > 0.0) || !std::isfinite(n2)) {
      fail(t.get(key), prefix + "." + key,
           fmt::format("{}.{}: must be a nonzero vector ({})", prefix, key, meaning));
    }
  }

  // The table `key` of `t` (named `path` in messages), its keys checked; nullptr when absent,
  // an error naming it when it is not a table.
  const toml::table* sub_table(const toml::table& t, std::string_view key,
                               const std::string& path) const {
    const toml::node* n = t.get(key);
    if (n == nullptr) return nullptr;
    const toml::table* table = n->as_table();
    if (table == nullptr) {
      fail(n, path, fmt::format("{}: expected a table ([{}]), found {}", path, path, describe(*n)));
    }
    check_keys(*table, path);
    return table;
  }

  // [boundary.outlet]: its plane and insertion region (required together), the velocity and
  // seed of the particles put back. Whether the plane cuts a periodic axis and where the region
  // lies are checked with the box (Environment::check).
  void read_outlet(const toml::table& t, int dimension, OutletConfig& outlet) const {
    const toml::table* table = sub_table(t, "outlet", "boundary.outlet");
    if (table == nullptr) return;
    read_group(*table, "boundary.outlet", outlet_keys(), &outlet, &dimension);
    require_vectors(*table, "boundary.outlet", {"normal", "point", "insert_lower", "insert_upper"},
                    dimension);
    require_nonzero(*table, "boundary.outlet", "normal", outlet.normal,
                    "it points to the side the particles come from");
  }

  void read_boundary(const toml::table& t, int dimension, const ContactConfig& contact,
                     BoundaryConfig& b) const {
    constexpr std::string_view p = "boundary";
    // Who claims each face: the node (for error locations), its key, and what it makes it.
    struct Claim {
      const toml::node* node = nullptr;
      std::string key;
      bool wall = false;
    };
    std::array<Claim, 6> claims{};

    const std::vector<const toml::table*> tables = table_array(t, p, "wall");
    for (std::size_t i = 0; i < tables.size(); ++i) {
      const toml::table& wt = *tables[i];
      const std::string prefix = fmt::format("boundary.wall[{}]", i);
      const std::string face_key = prefix + ".face";
      WallConfig w;
      w.contact = contact;
      const toml::node* n_face = get_string(wt, prefix, "face", w.face);
      if (n_face == nullptr) {
        fail(tables[i], face_key,
             fmt::format("missing required key '{}' (one of {})", face_key,
                         box_faces(dimension).names()));
      }
      const int f = face_index(n_face, face_key, w.face, dimension);
      if (claims[static_cast<std::size_t>(f)].node != nullptr) {
        fail(n_face, face_key,
             fmt::format("{}: face {} is listed twice (already {})", face_key, w.face,
                         claims[static_cast<std::size_t>(f)].key));
      }
      claims[static_cast<std::size_t>(f)] = {n_face, prefix, true};

      read_contact(wt, prefix, w.contact);
      // In-plane components of the velocity slide the wall, the normal one moves it as a
      // piston; whether approaching walls leave room is checked as the run goes. Beyond 1e9 rad
      // a double no longer resolves the phase to 1e-7.
      read_group(wt, prefix, wall_keys(), &w, &dimension);
      b.walls.push_back(std::move(w));
    }

    for_each_surface_table(b.surfaces, [&](auto table, auto& entries) {
      const std::vector<const toml::table*> given = table_array(t, p, table.key);
      for (std::size_t i = 0; i < given.size(); ++i) {
        const EntryReading entry(*this, *given[i], fmt::format("boundary.{}[{}]", table.key, i),
                                 dimension, contact);
        typename decltype(table)::Config config;
        table.read(entry, config);
        entries.push_back(std::move(config));
      }
    });

    read_group(t, std::string(p), boundary_keys(), &b, &dimension);
    const toml::table none;
    const toml::table* container = sub_table(t, "container", "boundary.container");
    read_group(container != nullptr ? *container : none, "boundary.container", container_keys(),
               &b.container, &dimension);
    read_outlet(t, dimension, b.outlet);
    const toml::node* n_open = t.get("open");
    for (std::size_t i = 0; i < b.open.size(); ++i) {
      const std::string& face = b.open[i];
      const toml::node* node = element_of(n_open, i);
      const std::string key = fmt::format("boundary.open[{}]", i);
      const auto f = static_cast<std::size_t>(face_index(node, key, face, dimension));
      if (claims[f].node != nullptr) {
        fail(node, "boundary.open",
             claims[f].wall
                 ? fmt::format("{}: face {} is a wall ({}); a face is a wall or open, not both",
                               key, face, claims[f].key)
                 : fmt::format("{}: face {} is listed twice (already {})", key, face,
                               claims[f].key));
      }
      claims[f] = {node, key, false};
    }

    const toml::node* n_shear = t.get("shear_rate");
    for (std::size_t f = 0; n_shear != nullptr && b.shear_rate != 0.0 && f < 4; ++f) {
      if (claims[f].node != nullptr) {
        fail(n_shear, "boundary.shear_rate",
             fmt::format("boundary.shear_rate: Lees-Edwards shear needs periodic x (flow) and y "
                         "(gradient) axes, but face {} is {} ({})",
                         face_name(f), claims[f].wall ? "a wall" : "open", claims[f].key));
      }
    }

    // An axis is periodic (no wall, not open) or bounded at both ends.
    for (std::size_t axis = 0; axis < static_cast<std::size_t>(dimension); ++axis) {
      for (std::size_t side = 0; side < 2; ++side) {
        const Claim& here = claims[2 * axis + side];
        const Claim& there = claims[2 * axis + 1 - side];
        if (here.node == nullptr || there.node != nullptr) continue;
        const std::string_view face = face_name(2 * axis + side);
        const std::string_view other = face_name(2 * axis + 1 - side);
        fail(here.node, here.wall ? here.key + ".face" : std::string("boundary.open"),
             fmt::format(
                 "boundary: face {} is {} but {} is neither a wall nor in boundary.open; "
                 "add one (or {} to keep {} periodic)",
                 face, here.wall ? "a wall" : "open", other,
                 here.wall ? "remove the wall" : fmt::format("remove {} from boundary.open", face),
                 axis_name(axis)));
      }
    }
  }

  // The keys of a potential at `prefix` ("potential[i]", "bond[i]"), its kind among `kinds`.
  void read_potential_spec(const toml::table& t, const std::string& prefix,
                           const Choices<PotentialKind>& kinds, PotentialSpec& spec) const {
    const toml::node* n_kind = get_string(t, prefix, "kind", spec.kind);
    if (n_kind == nullptr) {
      fail(&t, prefix + ".kind",
           fmt::format("missing required key '{}.kind' (one of: {})", prefix, kinds.names()));
    }
    require_choice(n_kind, prefix + ".kind", spec.kind, choice_names(kinds));
    read_group(t, prefix, potential_keys(), &spec, nullptr);
    const bool spring_dashpot = potential_kinds().is(spec.kind, PotentialKind::kSpringDashpot);
    if (spring_dashpot) {
      // Equal steps with midpoint energies always: the dashpot per step assumes them.
      for (const std::string_view key : {"placement", "shell_energy"}) {
        if (const toml::node* node = t.get(key)) {
          fail(node, join_key(prefix, key),
               fmt::format("{}.{}: spring_dashpot steps are always of equal width with the "
                           "spring's energy at each step's middle; remove the key",
                           prefix, key));
        }
      }
    }
    for (const KeyDecl& d : spring_dashpot_keys().keys) {
      const toml::node* node = t.get(d.name);
      if (node != nullptr && !spring_dashpot) {
        fail(node, join_key(prefix, d.name),
             fmt::format("{}.{}: applies to kind = \"spring_dashpot\" only", prefix, d.name));
      }
    }
    if (t.get("damping") != nullptr && t.get("restitution") != nullptr) {
      fail(t.get("restitution"), prefix + ".restitution",
           fmt::format("{}.restitution: give damping or restitution, not both", prefix));
    }
    read_group(t, prefix, spring_dashpot_keys(), &spec, nullptr);
  }

  void read_potentials(const toml::table& root, const std::vector<SpeciesConfig>& species,
                       std::vector<PairPotentialConfig>& out) const {
    const std::vector<const toml::table*> tables = table_array(root, "", "potential");
    for (std::size_t i = 0; i < tables.size(); ++i) {
      const std::string prefix = fmt::format("potential[{}]", i);
      const std::string species_key = prefix + ".species";
      PairPotentialConfig pc;
      const toml::node* n_species = get_strings(*tables[i], prefix, "species", pc.species);
      if (n_species != nullptr && pc.species.size() != 2) {
        fail(n_species, species_key,
             fmt::format("{}: expected 2 species names (or no key: every pair), got {}",
                         species_key, pc.species.size()));
      }
      for (std::size_t k = 0; k < pc.species.size(); ++k) {
        const bool declared =
            std::any_of(species.begin(), species.end(),
                        [&](const SpeciesConfig& s) { return s.name == pc.species[k]; });
        if (!declared) {
          std::vector<std::string_view> known;
          for (const SpeciesConfig& s : species) known.push_back(s.name);
          fail(element_of(n_species, k), species_key,
               fmt::format("{}: unknown species '{}' (declared species: {})", species_key,
                           pc.species[k], join_words(known)));
        }
      }
      for (std::size_t j = 0; j < out.size(); ++j) {
        const auto& other = out[j].species;
        const bool same =
            other.size() == pc.species.size() &&
            (other.empty() || (other[0] == pc.species[0] && other[1] == pc.species[1]) ||
             (other[0] == pc.species[1] && other[1] == pc.species[0]));
        if (same) {
          fail(n_species != nullptr ? n_species : tables[i], species_key,
               fmt::format("{}: the same pair{} is already given by potential[{}]", prefix,
                           pc.species.empty() ? "s (all)" : "", j));
        }
      }
      read_potential_spec(*tables[i], prefix, pair_potential_kinds(), pc.potential);
      out.push_back(std::move(pc));
    }
  }

  void read_bonds(const toml::table& root, std::vector<BondConfig>& out) const {
    const std::vector<const toml::table*> tables = table_array(root, "", "bond");
    for (std::size_t i = 0; i < tables.size(); ++i) {
      const std::string prefix = fmt::format("bond[{}]", i);
      BondConfig bc;
      const toml::node* n_type = get_string(*tables[i], prefix, "type", bc.type);
      for (std::size_t j = 0; j < out.size(); ++j) {
        if (out[j].type == bc.type) {
          fail(n_type != nullptr ? n_type : tables[i], prefix + ".type",
               fmt::format("{}.type: bond type '{}' is already given by bond[{}]", prefix, bc.type,
                           j));
        }
      }
      bc.potential.kind = "";
      read_potential_spec(*tables[i], prefix, bond_potential_kinds(), bc.potential);
      out.push_back(std::move(bc));
    }
  }

  // A soft law at `prefix` ("soft", "soft.pair[i]"). On entry `law` holds the law inherited
  // from [soft] (the defaults for [soft] itself); the keys present replace its values. A pair
  // that gives damping / dissipation drops an inherited restitution and vice versa.
  void read_soft_law(const toml::table& t, const std::string& prefix, SoftLawConfig& law) const {
    const auto path = [&](std::string_view key) { return join_key(prefix, key); };
    const bool pair = prefix != "soft";
    read_group(t, prefix, soft_law_keys(), &law, nullptr);
    const toml::node* n_model = t.get("model");
    const toml::node* n_k = t.get("stiffness");
    const toml::node* n_gamma = t.get("damping");
    const toml::node* n_young = t.get("young");
    const toml::node* n_poisson = t.get("poisson");
    const toml::node* n_a = t.get("dissipation");
    const toml::node* n_e = t.get("restitution");
    const toml::node* n_speed = t.get("restitution_speed");
    if (n_model == nullptr && law.model.empty()) {
      fail(&t, path("model"),
           fmt::format("missing required key '{}' (\"dashpot\" or \"hertz\"): [soft] makes every "
                       "contact soft",
                       path("model")));
    }
    const bool dashpot = soft_models().is(law.model, SoftModel::LinearDashpot);
    // Keys of the other model given here are an error (inherited ones are just not used).
    const std::pair<const toml::node*, std::string_view> foreign[] = {
        {n_young, "young"},   {n_poisson, "poisson"},
        {n_a, "dissipation"}, {n_speed, "restitution_speed"},
        {n_k, "stiffness"},   {n_gamma, "damping"}};
    for (const auto& [node, key] :
         dashpot ? std::span(foreign).first(4) : std::span(foreign).last(2)) {
      if (node != nullptr) {
        fail(node, path(key),
             fmt::format("{}: not a key of model \"{}\" (dashpot: stiffness, damping or "
                         "restitution; hertz: young, poisson, dissipation or restitution with "
                         "restitution_speed)",
                         path(key), law.model));
      }
    }
    const toml::node* n_dissipative = dashpot ? n_gamma : n_a;
    const std::string_view dissipative_key = dashpot ? "damping" : "dissipation";
    double& dissipative = dashpot ? law.damping : law.dissipation;
    if (n_dissipative != nullptr && n_e != nullptr && dissipative > 0.0 && law.restitution > 0.0) {
      fail(n_e, path("restitution"),
           fmt::format("{}: give either {} or restitution, not both", path("restitution"),
                       path(dissipative_key)));
    }
    if (pair && n_dissipative != nullptr && n_e == nullptr) law.restitution = 0.0;
    if (pair && n_e != nullptr && n_dissipative == nullptr) dissipative = 0.0;
    // Only positive finite parameters make a contact law.
    if (dashpot) {
      if (n_k == nullptr && law.stiffness == 0.0) {
        fail(n_model != nullptr ? n_model : &t, path("stiffness"),
             fmt::format("missing required key '{}' (the spring constant k of model "
                         "\"dashpot\", > 0)",
                         path("stiffness")));
      }
      check_rule_range(n_k, path("stiffness"), law.stiffness);
      check_rule_range(n_gamma, path("damping"), law.damping);
    } else {
      if (n_young == nullptr && law.young == 0.0) {
        fail(n_model != nullptr ? n_model : &t, path("young"),
             fmt::format("missing required key '{}' (Young's modulus of model \"hertz\", > 0)",
                         path("young")));
      }
      check_rule_range(n_young, path("young"), law.young);
      check_rule_range(n_poisson, path("poisson"), law.poisson);
      check_rule_range(n_a, path("dissipation"), law.dissipation);
      check_rule_range(n_speed, path("restitution_speed"), law.restitution_speed);
    }
    if (!(law.restitution == 0.0 || kSoftRestitutionDomain.contains(law.restitution)) ||
        (n_e != nullptr && law.restitution == 0.0)) {
      fail(n_e, path("restitution"),
           fmt::format("{}: must be {} (the head-on coefficient of restitution{}), got {}",
                       path("restitution"), kSoftRestitutionDomain.text(),
                       dashpot ? "" : " at restitution_speed", law.restitution));
    }
  }

  void read_soft(const toml::table& t, const std::vector<SpeciesConfig>& species,
                 SoftConfig& soft) const {
    constexpr std::string_view p = "soft";
    read_soft_law(t, std::string(p), soft.law);
    // The nodes are integrated to 1e-13: below 1e-10 no table can be checked to its tolerance.
    read_group(t, std::string(p), soft_keys(), &soft, nullptr);
    const std::vector<const toml::table*> tables = table_array(t, p, "pair");
    for (std::size_t i = 0; i < tables.size(); ++i) {
      const std::string prefix = fmt::format("soft.pair[{}]", i);
      std::vector<std::array<std::string, 2>> given;
      for (const SoftPairConfig& other : soft.pairs) given.push_back(other.species);
      SoftPairConfig pair;
      pair.species = read_species_pair(*tables[i], prefix, "soft.pair", species, given);
      pair.law = soft.law;
      read_soft_law(*tables[i], prefix, pair.law);
      soft.pairs.push_back(std::move(pair));
    }
  }

  // The first key of a contact law that differs from the elastic, smooth default ("" if none).
  static std::string_view non_default_contact_key(const ContactConfig& c) {
    const ContactConfig hard{};
    if (c.restitution != hard.restitution) return "restitution";
    if (c.restitution_model != hard.restitution_model) return "restitution_model";
    if (c.restitution_speed != hard.restitution_speed) return "restitution_speed";
    if (!c.restitution_table.empty()) return "restitution_table";
    if (c.tangential_restitution != hard.tangential_restitution) return "tangential_restitution";
    if (c.friction != hard.friction) return "friction";
    if (c.elastic_below_speed != hard.elastic_below_speed) return "elastic_below_speed";
    return {};
  }

  // The node at a dotted path of plain tables ("contact.restitution"), or nullptr.
  static const toml::node* node_at(const toml::table& root, std::string_view path) {
    return root.at_path(path).node();
  }

  // Fixed grains (system.species[].fixed): the event engine meets them as sleepers that never
  // wake (docs/physics.md#fixed-grains); what that cannot be combined with (yet) is refused.
  void check_fixed_species(const toml::table& root, const Config& c) const {
    std::size_t fixed = 0, last = 0;
    for (std::size_t s = 0; s < c.system.species.size(); ++s)
      if (c.system.species[s].fixed) ++fixed, last = s;
    if (fixed == 0) return;
    const std::string key = fmt::format("system.species[{}].fixed", last);
    const toml::node* n_fixed = node_at(root, fmt::format("system.species[{}].fixed", last));
    const auto conflict = [&](std::string_view other, std::string_view why) {
      const toml::node* n = node_at(root, other);
      fail(n != nullptr ? n : n_fixed, key,
           fmt::format("{}: fixed grains cannot be combined with {} ({})", key, other, why));
    };
    if (fixed == c.system.species.size()) {
      fail(n_fixed, key,
           fmt::format("{}: every species is fixed: nothing would move (leave at least one "
                       "species free)",
                       key));
    }
    if (c.soft.enabled())
      conflict("soft.model", "soft contacts and the DEM meet no fixed grain yet");
    if (!c.potentials.empty())
      conflict("potential", "a fixed grain would miss its steps, as a sleeper would");
    if (!c.bonds.empty()) conflict("bond", "a fixed grain would miss its steps");
    if (c.boundary.shear_rate != 0.0)
      conflict("boundary.shear_rate", "the sheared images of a fixed grain would move");
    if (!driving_kinds().is(c.driving.kind, DrivingKind::kNone))
      conflict("driving.kind", "a kick would set a fixed grain moving");
    if (c.analysis.mutual_diffusion) {
      conflict("analysis.mutual_diffusion", "interdiffusion is defined for species that all move");
    }
    // Not yet measured over the moving particles alone (they would count the fixed grains as
    // particles at rest).
    if (c.analysis.velocity_distribution)
      conflict("analysis.velocity_distribution", "not yet measured without the fixed grains");
    if (!c.output.profile_axis.empty())
      conflict("output.profile_axis", "not yet measured without the fixed grains");
    if (c.analysis.msd_viscosity > 0.0) {
      conflict("analysis.msd_viscosity",
               "the Yeh-Hummer correction assumes a fluid whose momentum is conserved");
    }
    // A fixed grain predicts no wall contacts (as a sleeper): a wall moving along its normal
    // would reach it unseen.
    const auto moves = [&](const WallConfig& w, std::string_view prefix) {
      const char* why = "a fixed grain would not see the moving wall coming";
      if (w.amplitude > 0.0 && w.frequency > 0.0)
        conflict(fmt::format("{}.amplitude", prefix), why);
      if (w.mass > 0.0) conflict(fmt::format("{}.mass", prefix), why);
      if (!w.velocity.empty()) {
        const int axis = face_number(box_faces(c.system.dimension).at(w.face)) / 2;
        if (axis < static_cast<int>(w.velocity.size()) && w.velocity[axis] != 0.0)
          conflict(fmt::format("{}.velocity", prefix), why);
      }
    };
    for (std::size_t w = 0; w < c.boundary.walls.size(); ++w)
      moves(c.boundary.walls[w], fmt::format("boundary.wall[{}]", w));
    for_each_surface_table(c.boundary.surfaces, [&](auto table, const auto& entries) {
      for (std::size_t k = 0; k < entries.size(); ++k) {
        if (const std::optional<TableObstacle> moving = table.normal_motion(entries[k]))
          conflict(fmt::format("boundary.{}[{}]{}", table.key, k, moving->key), moving->why);
      }
    });
  }

  // [boundary.outlet]: what a particle that jumps back to the insertion region cannot be
  // combined with (yet).
  void check_outlet(const toml::table& root, const Config& c) const {
    if (c.boundary.outlet.normal.empty()) return;
    const auto conflict = [&](std::string_view other, std::string_view why) {
      const toml::node* n = node_at(root, other);
      fail(n != nullptr ? n : node_at(root, "boundary.outlet"), std::string(other),
           fmt::format("{}: an outlet (boundary.outlet) cannot be combined with {} ({})", other,
                       other, why));
    };
    if (c.soft.enabled() && !integrators().is(c.run.integrator, IntegratorKind::kDem))
      conflict("soft.model",
               "the event engine's soft spheres have no outlets yet; the DEM, run.integrator = "
               "\"dem\", has");
    if (c.boundary.shear_rate != 0.0) conflict("boundary.shear_rate", "not combined yet");
    if (!c.potentials.empty())
      conflict("potential", "a particle put back would break the zones of its pairs");
    if (!c.bonds.empty()) conflict("bond", "a particle put back would break its bonds");
    const char* why = "a particle put back jumps, so its displacement means nothing";
    if (c.analysis.transport) conflict("analysis.transport", why);
    if (c.analysis.msd) conflict("analysis.msd", why);
    if (c.analysis.mutual_diffusion) conflict("analysis.mutual_diffusion", why);
  }

  // [compress] (docs/physics.md#growing-spheres): a target, and a periodic box of hard cores.
  void check_compress(const toml::table& root, const Config& c) const {
    const CompressConfig& k = c.compress;
    if (root.contains("compress") && !k.on()) {
      fail(node_at(root, "compress"), "compress",
           "compress: give what to grow to: compress.packing_fraction, compress.pressure or "
           "compress.jammed = true");
    }
    if (!k.on()) return;
    const auto conflict = [&](std::string_view other, std::string_view why) {
      const toml::node* n = node_at(root, other);
      fail(n != nullptr ? n : node_at(root, "compress"), std::string(other),
           fmt::format("{}: compression ([compress]) cannot be combined with {} ({})", other, other,
                       why));
    };
    if (const auto obstacle = compression_obstacle(c)) conflict(obstacle->key, obstacle->why);
    if (k.packing_fraction > 0.0 && c.system.initial_state.empty() &&
        !(k.packing_fraction > c.system.packing_fraction)) {
      fail(node_at(root, "compress.packing_fraction"), "compress.packing_fraction",
           fmt::format("compress.packing_fraction = {} is not above system.packing_fraction = {}: "
                       "compression only grows the particles",
                       k.packing_fraction, c.system.packing_fraction));
    }
  }

  // What a wall with mass (a lid, a container) cannot be combined with (yet), each passed to
  // conflict(key, why), which names the wall's own key.
  template <class Conflict>
  static void refuse_with_moving_mass(const Config& c, Conflict&& conflict) {
    if (c.soft.enabled() && !integrators().is(c.run.integrator, IntegratorKind::kDem)) {
      conflict("soft.model",
               "the event engine's soft spheres meet no wall with mass yet; the DEM, "
               "run.integrator = \"dem\", does");
    }
    if (c.boundary.shear_rate != 0.0) conflict("boundary.shear_rate", "not combined yet");
    if (c.analysis.transport) conflict("analysis.transport", "momentum is not conserved");
  }

  // Walls with mass (boundaries/wall_body.hpp): face walls of the event engine whose motion
  // is their own; what that cannot be combined with (yet) is refused.
  void check_wall_masses(const toml::table& root, const Config& c) const {
    for (std::size_t k = 0; k < c.boundary.walls.size(); ++k) {
      const WallConfig& w = c.boundary.walls[k];
      const std::string prefix = fmt::format("boundary.wall[{}]", k);
      const auto key_node = [&](std::string_view key) {
        return node_at(root, fmt::format("{}.{}", prefix, key));
      };
      if (w.mass == 0.0) {
        if (w.force != 0.0) {
          fail(key_node("force"), prefix + ".force",
               fmt::format("{}.force: a force moves only a wall with mass (set {}.mass)", prefix,
                           prefix));
        }
        continue;
      }
      const auto conflict = [&](std::string_view key, std::string_view why) {
        const std::string name = std::string(key).find('.') == std::string::npos
                                     ? fmt::format("{}.{}", prefix, key)
                                     : std::string(key);
        const toml::node* n = node_at(root, name);
        fail(n != nullptr ? n : key_node("mass"), name,
             fmt::format("{}: a wall with mass ({}.mass) cannot be combined with {} ({})", name,
                         prefix, name, why));
      };
      if (!w.velocity.empty())
        for (double u : w.velocity)
          if (u != 0.0) conflict("velocity", "its motion follows from the impulses it takes");
      if (w.amplitude > 0.0 && w.frequency > 0.0)
        conflict("amplitude", "its motion follows from the impulses it takes");
      refuse_with_moving_mass(c, conflict);
    }
  }

  // [boundary.container]: the walls of one axis joined as one body of mass M on a spring to a
  // moving anchor (boundaries/wall_spring.hpp); what it needs and cannot be combined with.
  void check_container(const toml::table& root, const Config& c) const {
    const ContainerConfig& box = c.boundary.container;
    const auto key = [](std::string_view k) { return fmt::format("boundary.container.{}", k); };
    const auto refuse = [&](std::string_view k, const std::string& why) {
      const toml::node* n = node_at(root, key(k));
      fail(n != nullptr ? n : node_at(root, "boundary.container"), key(k),
           fmt::format("{}: {}", key(k), why));
    };
    if (box.axis.empty()) {
      if (!(box == ContainerConfig{})) {
        refuse("axis",
               "the container's keys are given but no axis (set boundary.container.axis to the "
               "axis whose two walls form the container)");
      }
      return;
    }
    if (!axes(c.system.dimension).contains(box.axis)) {
      refuse("axis", fmt::format("'{}' is not an axis of the box ({})", box.axis,
                                 axes(c.system.dimension).names(", ", " or ")));
    }
    const std::string lo = fmt::format("{}-", box.axis), hi = fmt::format("{}+", box.axis);
    for (const std::string& face : {lo, hi}) {
      const auto wall = std::find_if(c.boundary.walls.begin(), c.boundary.walls.end(),
                                     [&](const WallConfig& w) { return w.face == face; });
      if (wall == c.boundary.walls.end()) {
        refuse("axis", fmt::format("the container is the walls {} and {}, but face {} has no "
                                   "wall (add a [[boundary.wall]] with face = \"{}\")",
                                   lo, hi, face, face));
      }
      const std::size_t k = static_cast<std::size_t>(wall - c.boundary.walls.begin());
      const bool slides = std::any_of(wall->velocity.begin(), wall->velocity.end(),
                                      [](double u) { return u != 0.0; });
      const bool moves = wall->mass != 0.0 || wall->force != 0.0 ||
                         (wall->amplitude > 0.0 && wall->frequency > 0.0) || slides;
      if (moves) {
        refuse("axis", fmt::format("the container moves its walls; boundary.wall[{}] ({}) must "
                                   "not have a mass, force, vibration or velocity of its own",
                                   k, face));
      }
    }
    if (!(box.mass > 0.0)) refuse("mass", "a container needs its mass (> 0)");
    const double k = box.spring_stiffness, damping = box.spring_damping;
    if (k == 0.0) {
      for (const auto& [name, value] :
           {std::pair{"spring_damping", damping}, std::pair{"drive_amplitude", box.drive_amplitude},
            std::pair{"drive_frequency", box.drive_frequency},
            std::pair{"drive_phase", box.drive_phase}}) {
        if (value != 0.0) refuse(name, "needs a spring (boundary.container.spring_stiffness > 0)");
      }
    }
    const WallSpring spring{k, damping, box.drive_amplitude,
                            2.0 * std::numbers::pi * box.drive_frequency, box.drive_phase};
    switch (spring_problem(spring, box.mass)) {
      case SpringProblem::kOverdamped:
        refuse("spring_damping",
               fmt::format("{} is at or above critical damping 2 sqrt(k M) = {:.6g}: only an "
                           "underdamped spring is supported",
                           damping, 2.0 * std::sqrt(k * box.mass)));
        return;
      case SpringProblem::kResonant:
        refuse("drive_frequency",
               "drives an undamped spring at its resonance sqrt(k / M) / 2 pi: its amplitude "
               "would grow without bound (add spring_damping or move the frequency)");
        return;
      case SpringProblem::kNone:
        break;
    }
    const auto conflict = [&](std::string_view other, std::string_view why) {
      const toml::node* n = node_at(root, other);
      fail(n != nullptr ? n : node_at(root, key("axis")), std::string(other),
           fmt::format("{}: a container (boundary.container) cannot be combined with {} ({})",
                       other, other, why));
    };
    refuse_with_moving_mass(c, conflict);
    for (std::size_t s = 0; s < c.system.species.size(); ++s) {
      if (c.system.species[s].fixed) {
        conflict(fmt::format("system.species[{}].fixed", s),
                 "a fixed grain would not see the moving wall coming");
      }
    }
  }

  // What soft spheres and the DEM integrator cannot be combined with (yet).
  void check_soft_and_dem(const toml::table& root, const Config& c) const {
    const toml::node* n_model = node_at(root, "soft.model");
    if (c.soft.enabled()) {
      const auto conflict = [&](std::string_view key, std::string_view why) {
        const toml::node* n = node_at(root, key);
        fail(n != nullptr ? n : n_model, key,
             fmt::format("{}: not allowed with soft spheres (soft.model = \"{}\"): {}", key,
                         c.soft.law.model, why));
      };
      const std::string_view laws =
          "soft contacts replace the [contact] laws (set the dissipation in [soft])";
      if (const std::string_view key = non_default_contact_key(c.interactions.contact);
          !key.empty()) {
        const bool rough = key == "tangential_restitution" || key == "friction";
        conflict(join_key("contact", key), rough ? "soft spheres are frictionless (smooth)" : laws);
      }
      if (c.interactions.tc != 0.0) conflict("contact.tc", laws);
      if (!c.interactions.pairs.empty()) conflict("contact.pair", "use [[soft.pair]] instead");
      for (std::size_t w = 0; w < c.boundary.walls.size(); ++w) {
        if (const std::string_view key = non_default_contact_key(c.boundary.walls[w].contact);
            !key.empty()) {
          conflict(fmt::format("boundary.wall[{}].{}", w, key),
                   "soft contacts with walls use the [soft] material");
        }
      }
      if (!c.potentials.empty())
        conflict("potential", "stepped potentials and soft spheres do not mix");
      if (!c.bonds.empty()) conflict("bond", "stepped potentials and soft spheres do not mix");
      if (c.boundary.shear_rate != 0.0) {
        conflict("boundary.shear_rate",
                 "Lees-Edwards shear is not supported with soft spheres yet");
      }
      if (!integrators().is(c.run.integrator, IntegratorKind::kDem)) {
        const auto rough = [&](const SoftLawConfig& law, const std::string& prefix) {
          if (law.friction > 0.0) {
            const std::string key = prefix + ".friction";
            const toml::node* n = node_at(root, key);
            fail(n != nullptr ? n : n_model, key,
                 fmt::format("{}: friction is integrated by the DEM alone (the collision map is "
                             "that of smooth spheres); set run.integrator = \"dem\" or friction "
                             "= 0",
                             key));
          }
        };
        rough(c.soft.law, "soft");
        for (std::size_t p = 0; p < c.soft.pairs.size(); ++p)
          rough(c.soft.pairs[p].law, fmt::format("soft.pair[{}]", p));
      }
      if (!c.field.gravity.empty() && !integrators().is(c.run.integrator, IntegratorKind::kDem)) {
        conflict("field.gravity",
                 "the collision mapping is not defined under gravity (a soft contact under a "
                 "load does not end); use run.integrator = \"dem\"");
      }
    }
    check_analysis_keys(root, c.analysis);
    check_transport(root, c);
    if (c.analysis.mutual_diffusion && c.system.species.size() < 2 &&
        c.system.initial_state.empty()) {
      fail(node_at(root, "analysis.mutual_diffusion"), "analysis.mutual_diffusion",
           "analysis.mutual_diffusion: interdiffusion needs a mixture (two or more "
           "[[system.species]])");
    }
    if (c.analysis.msd && c.boundary.shear_rate != 0.0) {
      fail(node_at(root, "analysis.msd"), "analysis.msd",
           "analysis.msd: the mean-square displacement under Lees-Edwards shear is not measured "
           "yet (the streaming displacement would need subtracting); remove boundary.shear_rate "
           "or analysis.msd");
    }
    if (!integrators().is(c.run.integrator, IntegratorKind::kDem)) return;
    const toml::node* n_integrator = node_at(root, "run.integrator");
    const auto unsupported = [&](std::string_view key, std::string_view what) {
      const toml::node* n = node_at(root, key);
      fail(n != nullptr ? n : n_integrator, key,
           fmt::format("{}: {} not supported by the DEM integrator (run.integrator = \"dem\")", key,
                       what));
    };
    if (!c.soft.enabled()) {
      fail(n_integrator, "run.integrator",
           "run.integrator: \"dem\" integrates soft contact forces and needs a [soft] table "
           "(model = \"dashpot\" or \"hertz\")");
    }
    if (!c.boundary.open.empty()) unsupported("boundary.open", "open faces are");
    if (!driving_kinds().is(c.driving.kind, DrivingKind::kNone))
      unsupported("driving.kind", "driving is");
    if (c.run.validate) unsupported("run.validate", "engine validation is");
    if (c.analysis.msd)
      unsupported("analysis.msd", "the mean-square displacement (image counters) is");
  }

  // The Einstein-Helfand moments (engine/helfand_moments.hpp) need a conservative,
  // translation-invariant system; the obstacle is named by its key.
  void check_transport(const toml::table& root, const Config& c) const {
    if (!c.analysis.transport) return;
    const std::optional<TransportObstacle> obstacle = transport_obstacle(c);
    if (!obstacle) return;
    const toml::node* n = node_at(root, obstacle->key);
    fail(n != nullptr ? n : node_at(root, "analysis.transport"), obstacle->key,
         fmt::format("analysis.transport: {} ({}): the Einstein-Helfand moments need a "
                     "conservative periodic system; remove {} or analysis.transport",
                     obstacle->why, obstacle->key, obstacle->key));
  }

  // trajectory.gsd's options (docs/outputs.md): the fields are HOOMD's names, each once, with
  // the positions, and what the integrator has; log-spaced frames need their first lag, and
  // their own keys act only with them.
  void check_trajectory_keys(const toml::table& root, const Config& c) const {
    const OutputConfig& o = c.output;
    const toml::node* n_fields = node_at(root, "output.trajectory_fields");
    std::vector<std::string_view> seen;
    for (std::size_t i = 0; i < o.trajectory_fields.size(); ++i) {
      const std::string& name = o.trajectory_fields[i];
      const std::string path = fmt::format("output.trajectory_fields[{}]", i);
      const toml::node* n =
          n_fields != nullptr && n_fields->is_array() ? n_fields->as_array()->get(i) : n_fields;
      if (!trajectory_fields().contains(name)) {
        const bool hoomd = name == "orientation" || name == "angmom" || name == "charge" ||
                           name == "body" || name == "moment_inertia";
        fail(
            n, path,
            fmt::format("{}: '{}' is not a trajectory field{}; valid values: {}", path, shown(name),
                        hoomd ? " (a HOOMD field Kairos's spheres do not have: their spin is "
                                "angular_velocity)"
                              : "",
                        trajectory_fields().names()));
      }
      if (std::find(seen.begin(), seen.end(), name) != seen.end())
        fail(n, path, fmt::format("{}: '{}' is listed twice", path, name));
      seen.push_back(name);
      if (integrators().is(c.run.integrator, IntegratorKind::kDem) &&
          trajectory_fields().is(name, TrajectoryField::kImage)) {
        fail(n, path,
             fmt::format("{}: \"image\" is not written by the DEM integrator (run.integrator = "
                         "\"dem\"), which counts no periodic images yet",
                         path));
      }
    }
    if (!o.trajectory_fields.empty() &&
        std::find(seen.begin(), seen.end(), "position") == seen.end()) {
      fail(n_fields, "output.trajectory_fields",
           "output.trajectory_fields: must include \"position\" (a frame without positions is "
           "no trajectory frame)");
    }
    const bool log = trajectory_spacings().is(o.trajectory_spacing, TrajectorySpacing::kLog);
    for (const char* key :
         {"output.trajectory_frames_per_decade", "output.trajectory_log_period"}) {
      if (!log && node_at(root, key) != nullptr) {
        fail(node_at(root, key), key,
             fmt::format("{}: acts only with output.trajectory_spacing = \"log\"", key));
      }
    }
    if (!log) return;
    if (!(o.trajectory_interval > 0.0)) {
      const toml::node* n = node_at(root, "output.trajectory_interval");
      fail(n != nullptr ? n : node_at(root, "output.trajectory_spacing"),
           "output.trajectory_interval",
           "output.trajectory_interval: log-spaced frames (output.trajectory_spacing = \"log\") "
           "need their first lag: give trajectory_interval (0, automatic, is for linear frames)");
    }
    if (o.trajectory_log_period > 0.0 && !(o.trajectory_log_period > o.trajectory_interval)) {
      fail(node_at(root, "output.trajectory_log_period"), "output.trajectory_log_period",
           fmt::format("output.trajectory_log_period = {}: the period of the log-spaced "
                       "sequence must be longer than its first lag (output.trajectory_interval "
                       "= {})",
                       o.trajectory_log_period, o.trajectory_interval));
    }
  }

  // An analysis's own keys act only with that analysis on (an error naming the key, never a key
  // silently ignored), and the MSD's fit window must be a window.
  void check_analysis_keys(const toml::table& root, const AnalysisConfig& a) const {
    const AnalysisConfig d;
    const bool structure = a.rdf || a.structure_factor || a.bond_order || a.velocity_distribution;
    struct Needs {
      const char* key;
      bool given, on;
      const char* what;
    };
    const Needs keys[] = {
        {"analysis.vacf", a.vacf, a.msd, "analysis.msd = true"},
        {"analysis.msd_time", a.msd_time != d.msd_time, a.msd, "analysis.msd = true"},
        {"analysis.mutual_diffusion", a.mutual_diffusion, a.msd, "analysis.msd = true"},
        {"analysis.msd_interval", a.msd_interval != d.msd_interval, a.msd, "analysis.msd = true"},
        {"analysis.msd_particles", a.msd_particles != d.msd_particles, a.msd,
         "analysis.msd = true"},
        {"analysis.msd_fit_from", a.msd_fit_from != d.msd_fit_from, a.msd, "analysis.msd = true"},
        {"analysis.msd_fit_to", a.msd_fit_to != d.msd_fit_to, a.msd, "analysis.msd = true"},
        {"analysis.msd_viscosity", a.msd_viscosity != d.msd_viscosity, a.msd,
         "analysis.msd = true"},
        {"analysis.rdf_bins", a.rdf_bins != d.rdf_bins, a.rdf, "analysis.rdf = true"},
        {"analysis.rdf_max_distance", a.rdf_max_distance != d.rdf_max_distance, a.rdf,
         "analysis.rdf = true"},
        {"analysis.sk_max", a.sk_max != d.sk_max, a.structure_factor,
         "analysis.structure_factor = true"},
        {"analysis.bond_cutoff", a.bond_cutoff != d.bond_cutoff, a.bond_order,
         "analysis.bond_order = true"},
        {"analysis.interval", a.interval != d.interval, structure,
         "a structure analysis (rdf, structure_factor, bond_order or velocity_distribution)"},
        {"analysis.transport_interval", a.transport_interval != d.transport_interval, a.transport,
         "analysis.transport = true"},
        {"analysis.transport_fit_from", a.transport_fit_from != d.transport_fit_from, a.transport,
         "analysis.transport = true"},
        {"analysis.transport_fit_to", a.transport_fit_to != d.transport_fit_to, a.transport,
         "analysis.transport = true"}};
    for (const Needs& k : keys) {
      if (k.given && !k.on)
        fail(node_at(root, k.key), k.key, fmt::format("{}: acts only with {}", k.key, k.what));
    }
    // In collisions per particle: no velocity autocorrelation (the velocities of a cooling gas
    // decay) and no finite-size correction (a viscosity is per unit time).
    if (a.msd && msd_time_scales().at(a.msd_time) == MsdTime::kCollisions) {
      for (const auto& [key, given] : {std::pair{"analysis.vacf", a.vacf},
                                       {"analysis.msd_viscosity", a.msd_viscosity != 0.0}}) {
        if (given) {
          fail(node_at(root, key), key,
               fmt::format("{}: not with analysis.msd_time = \"collisions\" (the MSD against "
                           "collisions per particle); use msd_time = \"time\"",
                           key));
        }
      }
    }
    const auto window = [&](const char* from_key, double from, const char* to_key, double to) {
      if (from > 0.0 && to > 0.0 && !(from < to)) {
        fail(node_at(root, to_key), to_key,
             fmt::format("{} = {}: the fit window must end after it starts ({} = {})", to_key, to,
                         from_key, from));
      }
    };
    window("analysis.msd_fit_from", a.msd_fit_from, "analysis.msd_fit_to", a.msd_fit_to);
    window("analysis.transport_fit_from", a.transport_fit_from, "analysis.transport_fit_to",
           a.transport_fit_to);
  }

  void read_field(const toml::table& t, const int& dimension, FieldConfig& f) const {
    read_group(t, "field", field_keys(), &f, &dimension);  // no field: stored empty
  }

  void read_driving(const toml::table& t, DrivingConfig& d) const {
    read_group(t, "driving", driving_keys(), &d, nullptr);
    if (driving_kinds().is(d.kind, DrivingKind::kWhiteNoise) && !(d.strength > 0.0)) {
      const toml::node* n_strength = t.get("strength");
      fail(n_strength != nullptr ? n_strength : t.get("kind"), "driving.strength",
           "driving.strength: white_noise driving needs a strength > 0 (velocity variance per "
           "unit time)");
    }
  }

  void read_run(const toml::table& t, RunConfig& r) const {
    // Up to 1e9 collisions per particle: 1e18 collisions of the largest system still count in
    // 64 bits, and no run gets that far.
    read_group(t, "run", run_keys(), &r, nullptr);
    // One length per phase: in collisions per particle or in simulated time, not both.
    if (t.get("time") != nullptr && t.get("collisions_per_particle") != nullptr) {
      fail(t.get("time"), "run.time",
           "run.time and run.collisions_per_particle both give the production length: keep one");
    }
    if (t.get("equilibration_time") != nullptr &&
        t.get("equilibration_collisions_per_particle") != nullptr) {
      fail(t.get("equilibration_time"), "run.equilibration_time",
           "run.equilibration_time and run.equilibration_collisions_per_particle both give the "
           "equilibration length: keep one");
    }
    if (r.time_step > 0.0 && !integrators().is(r.integrator, IntegratorKind::kDem)) {
      fail(t.get("time_step"), "run.time_step",
           fmt::format("run.time_step: only used by the DEM integrator (run.integrator = \"dem\"; "
                       "it is \"{}\"), which has a time step",
                       r.integrator));
    }
  }

  void read_output(const toml::table& t, int dimension, OutputConfig& o) const {
    read_group(t, "output", output_keys(), &o, &dimension);
    if (!(o.profile_axis.empty() || axes(dimension).contains(o.profile_axis))) {
      fail(t.get("profile_axis"), "output.profile_axis",
           fmt::format("output.profile_axis: '{}' is not an axis of a {}D box (x, y{}, or \"\" for "
                       "no profile)",
                       o.profile_axis, dimension, dimension == 3 ? ", z" : ""));
    }
    if (o.directory.empty()) {
      fail(t.get("directory"), "output.directory", "output.directory: must not be empty");
    }
  }

  // The intervals' unit defaults to the production length's; automatic intervals (0) are
  // fractions of the production length, so they need the same unit.
  void resolve_interval_unit(const toml::table& t, const RunConfig& r, OutputConfig& o) const {
    const std::string length_unit = r.time > 0.0 ? "time" : "collisions";
    if (o.interval_unit.empty()) o.interval_unit = length_unit;
    if (o.interval_unit == length_unit) return;
    const char* automatic = !(o.thermo_interval > 0.0)       ? "thermo_interval"
                            : !(o.trajectory_interval > 0.0) ? "trajectory_interval"
                                                             : nullptr;
    if (automatic != nullptr) {
      fail(t.get("interval_unit"), "output.interval_unit",
           fmt::format("output.interval_unit = \"{}\" but the production length is in {} "
                       "(run.{}): the automatic output.{} (a fraction of that length) cannot be "
                       "converted; give it explicitly",
                       o.interval_unit, length_unit == "time" ? "simulated time" : "collisions",
                       length_unit == "time" ? "time" : "collisions_per_particle", automatic));
    }
  }
};

}  // namespace

Config parse_config(std::string_view toml_text, std::string_view source_name,
                    const std::vector<std::string>& overrides) {
  const std::string source =
      source_name.empty() ? std::string("<config>") : std::string(source_name);
  toml::table root;
  try {
    root = toml::parse(toml_text, source);
  } catch (const toml::parse_error& e) {
    throw InputError(fmt::format("{}:{}:{}: TOML syntax error: {}", source, e.source().begin.line,
                                 e.source().begin.column, one_line(e.description())));
  }
  std::vector<AppliedOverride> applied;
  applied.reserve(overrides.size());
  for (const std::string& text : overrides) applied.push_back(apply_override(root, text));
  return Reader(source, std::move(applied)).read(root);
}

namespace {

// Only a regular file is read: reading a FIFO would block until another process writes to it,
// and a directory or a device is never a config file. (A missing file is left to fopen.)
void require_regular_file(const std::filesystem::path& path) {
  using std::filesystem::file_type;
  std::error_code ec;
  const file_type type = std::filesystem::status(path, ec).type();
  if (ec || type == file_type::regular || type == file_type::not_found) return;
  const char* kind = type == file_type::directory                               ? "a directory"
                     : type == file_type::fifo                                  ? "a FIFO"
                     : type == file_type::character || type == file_type::block ? "a device"
                                                                                : "a special file";
  throw InputError(
      fmt::format("config file '{}' is not a regular file (it is {}): give the path of a TOML file",
                  path.string(), kind));
}

}  // namespace

std::string read_config_text(const std::filesystem::path& path) {
  const auto cannot_read = [&](const std::string& reason) {
    return InputError(fmt::format("cannot read config file '{}': {}", path.string(), reason));
  };
  require_regular_file(path);

  const std::unique_ptr<std::FILE, int (*)(std::FILE*)> file(std::fopen(path.c_str(), "rb"),
                                                             &std::fclose);
  if (!file) throw cannot_read(std::strerror(errno));
  std::string text;
  char buffer[1 << 16];
  std::size_t n = 0;
  while ((n = std::fread(buffer, 1, sizeof buffer, file.get())) > 0) text.append(buffer, n);
  if (std::ferror(file.get()) != 0) throw cannot_read(std::strerror(errno));
  return text;
}

Config load_config(const std::filesystem::path& path, const std::vector<std::string>& overrides) {
  return parse_config(read_config_text(path), path.string(), overrides);
}

}  // namespace kairos
