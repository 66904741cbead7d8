// Every config key (io/config_keys.hpp): where each group of src/io/keys/ is placed, and what
// the declarations give the reader, --set, the written config.toml and docs/config.md.
#include "io/config_keys.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cstdint>

#include "interactions/parameter_domain.hpp"
#include "interactions/potential_spec.hpp"
#include "io/config.hpp"
#include "io/config_choices.hpp"
#include "io/keys/key_tables.hpp"
#include "io/surface_tables.hpp"

namespace kairos {

namespace {

using namespace key_tables;

// Where each group appears: tables and their keys, in the order of the suggestions. A group
// placed `last` is suggested after every other key (an unknown 'restitution' elsewhere is
// offered contact.* and soft.* first).
struct Placement {
  std::string path;  // of the table
  KeyType type;      // kTable or kTableArray
  std::vector<PlacedGroup> groups;
};

std::vector<DeclaredKey> build() {
  std::vector<Placement> placements = {
      {"system", KeyType::kTable, {{&kSystemGroup}}},
      {"system.species", KeyType::kTableArray, {{&kSpeciesGroup}}},
      {"potential",
       KeyType::kTableArray,
       {{&kPotentialSpeciesGroup}, {&kPotentialGroup}, {&kSpringDashpotGroup, {}, true}}},
      {"bond", KeyType::kTableArray, {{&kBondTypeGroup}, {&kPotentialGroup, "potential"}}},
      {"contact", KeyType::kTable, {{&kContactLawGroup}, {&kContactGroup}}},
      {"contact.pair",
       KeyType::kTableArray,
       {{&kPairSpeciesGroup}, {&kContactLawGroup, "contact"}}},
      {"boundary", KeyType::kTable, {{&kBoundaryGroup}}},
      {"boundary.wall",
       KeyType::kTableArray,
       {{&kWallFaceGroup}, {&kContactLawGroup, "contact"}, {&kWallGroup}}},
      {"boundary.container", KeyType::kTable, {{&kContainerGroup}}},
      {"boundary.outlet", KeyType::kTable, {{&kOutletGroup}}},
      {"driving", KeyType::kTable, {{&kDrivingGroup}}},
      {"field", KeyType::kTable, {{&kFieldGroup}}},
      {"run", KeyType::kTable, {{&kRunGroup}}},
      {"soft", KeyType::kTable, {{&kSoftGroup}, {&kSoftLawGroup}}},
      {"soft.pair", KeyType::kTableArray, {{&kPairSpeciesGroup}, {&kSoftLawGroup, "soft"}}},
      {"output", KeyType::kTable, {{&kOutputGroup}}},
      {"analysis", KeyType::kTable, {{&kAnalysisGroup}}},
      {"compress", KeyType::kTable, {{&kCompressGroup}}},
  };
  // The surface tables (io/surface_tables.hpp) after [boundary.outlet].
  auto after = std::find_if(placements.begin(), placements.end(),
                            [](const Placement& p) { return p.path == "boundary.outlet"; }) +
               1;
  SurfaceTables::each([&](auto table) {
    using Table = typename decltype(table)::type;
    after = placements.insert(after, {fmt::format("boundary.{}", Table::key), KeyType::kTableArray,
                                      Table::placement()}) +
            1;
  });
  std::vector<DeclaredKey> out, last;
  for (const Placement& p : placements) {
    out.push_back({std::string(p.path), p.type, nullptr, nullptr, {}});
    const std::string prefix =
        p.type == KeyType::kTableArray ? std::string(p.path) + "[]" : std::string(p.path);
    if (p.type == KeyType::kTableArray)
      out.push_back({prefix, KeyType::kTable, nullptr, nullptr, {}});
    for (const PlacedGroup& g : p.groups) {
      for (const KeyDecl& d : g.group->keys) {
        (g.last ? last : out)
            .push_back(
                {prefix + "." + std::string(d.name), d.type, &d, g.group->defaults, g.shared_from});
      }
    }
  }
  out.insert(out.end(), last.begin(), last.end());
  return out;
}

// "system.species[3].name" -> "system.species[].name"
std::string schema_path(std::string_view path) {
  std::string out;
  for (std::size_t i = 0; i < path.size(); ++i) {
    out += path[i];
    if (path[i] == '[') {
      while (i + 1 < path.size() && path[i + 1] != ']') ++i;
    }
  }
  return out;
}

const char* const kSuperscripts[] = {"⁰", "¹", "²", "³", "⁴", "⁵", "⁶", "⁷", "⁸", "⁹"};

std::string scale_text(Scale scale) {
  switch (scale) {
    case Scale::kNone:
      return "";
    case Scale::kEnergy:
      return "kT";
    case Scale::kSpeed:
      return "v";
    case Scale::kTime:
      return "τ";
    case Scale::kRate:
      return "/ τ";
    case Scale::kLength:
      return "d";
    case Scale::kInverseLength:
      return "/ d";
    case Scale::kStiffness:
      return "kT / d²";
    case Scale::kModulus:
      return "kT / d³";
    case Scale::kCollisionRate:
      return "ω";
    case Scale::kBoxEdge:
      return "box edges";
    case Scale::kSpeedSquaredPerTime:
      return "v² / τ";
  }
  return "";
}

// The default of a key, as a TOML value in backquotes.
std::string doc_value(const KeyDecl& d, const void* defaults) {
  const Field& f = d.member;
  switch (f.cpp) {
    case CppType::kInt:
      return fmt::format("`{}`", f.of<int>(defaults));
    case CppType::kInt64:
      return fmt::format("`{}`", f.of<std::int64_t>(defaults));
    case CppType::kUint64:
      return fmt::format("`{}`", f.of<std::uint64_t>(defaults));
    case CppType::kDouble: {
      std::string s = fmt::format("{}", f.of<double>(defaults));
      if (s.find_first_of(".en") == std::string::npos) s += ".0";
      const auto e = s.find("e-0");  // 1e-06 -> 1e-6
      if (e != std::string::npos) s.erase(e + 2, 1);
      return fmt::format("`{}`", s);
    }
    case CppType::kString:
      return fmt::format("`\"{}\"`", f.of<std::string>(defaults));
    case CppType::kBool:
      return fmt::format("`{}`", f.of<bool>(defaults));
    case CppType::kDoubles:
    case CppType::kStrings:
    case CppType::kSpeedTable:
      break;
  }
  return "";
}

}  // namespace

const std::vector<DeclaredKey>& declared_keys() {
  static const std::vector<DeclaredKey> keys = build();
  return keys;
}

const DeclaredKey* find_declared(std::string_view path) {
  const std::string schema = schema_path(path);
  for (const DeclaredKey& k : declared_keys())
    if (k.path == schema) return &k;
  return nullptr;
}

const KeyGroup& system_keys() {
  return kSystemGroup;
}
const KeyGroup& species_keys() {
  return kSpeciesGroup;
}
const KeyGroup& contact_law_keys() {
  return kContactLawGroup;
}
const KeyGroup& contact_keys() {
  return kContactGroup;
}
const KeyGroup& boundary_keys() {
  return kBoundaryGroup;
}
const KeyGroup& wall_keys() {
  return kWallGroup;
}
const KeyGroup& container_keys() {
  return kContainerGroup;
}
const KeyGroup& outlet_keys() {
  return kOutletGroup;
}
const KeyGroup& field_keys() {
  return kFieldGroup;
}
const KeyGroup& driving_keys() {
  return kDrivingGroup;
}
const KeyGroup& run_keys() {
  return kRunGroup;
}
const KeyGroup& output_keys() {
  return kOutputGroup;
}
const KeyGroup& potential_keys() {
  return kPotentialGroup;
}
const KeyGroup& spring_dashpot_keys() {
  return kSpringDashpotGroup;
}
const KeyGroup& soft_law_keys() {
  return kSoftLawGroup;
}
const KeyGroup& soft_keys() {
  return kSoftGroup;
}
const KeyGroup& analysis_keys() {
  return kAnalysisGroup;
}
const KeyGroup& compress_keys() {
  return kCompressGroup;
}

std::string type_text(const KeyDecl& d) {
  switch (d.type) {
    case KeyType::kTable:
      return "table";
    case KeyType::kTableArray:
      return "array of tables";
    case KeyType::kInteger:
    case KeyType::kUnsigned:
      return "integer";
    case KeyType::kFloat:
      return "float";
    case KeyType::kString:
      return "string";
    case KeyType::kBoolean:
      return "boolean";
    case KeyType::kFloats:
      return "array of floats";
    case KeyType::kVector:
      return "array of D floats";
    case KeyType::kStrings:
      return "array of strings";
    case KeyType::kSpeciesPair:
      return "array of 2 strings";
    case KeyType::kSpeedTable:
      return "array of [speed, e] pairs";
  }
  return "";
}

std::string default_text(const DeclaredKey& key) {
  if (key.shared_from == "potential") return "as in `[[potential]]`";
  if (!key.shared_from.empty()) return fmt::format("from `[{}]`", key.shared_from);
  const KeyDecl& d = *key.decl;
  if (!d.default_text.empty() || key.defaults == nullptr || !d.member)
    return std::string(d.default_text);
  return doc_value(d, key.defaults);
}

std::string doc_number(double v) {
  if (v == kInf) return "∞";
  if (v < 0.0) return "−" + doc_number(-v);
  if (v == kMaxParticles) return "2³¹ − 1";
  if (v == 1e-12 || v == 1e-10 || v == 1e-9 || v == 1e-6 || v == 1e3 || v == 1e6 || v == 1e9 ||
      v == 1e13 || v == 1e15) {
    const int e = static_cast<int>(std::lround(std::log10(v)));
    std::string out = "10";
    if (e < 0) out += "⁻";
    for (const char c : std::to_string(std::abs(e))) out += kSuperscripts[c - '0'];
    return out;
  }
  if (v == 100000.0) return "100 000";
  return fmt::format("{}", v);
}

std::string range_text(const KeyDecl& d) {
  const Range& r = d.range;
  if (!r.bounded()) return "";
  const std::string unit = scale_text(r.scale);
  std::string out;
  if (!std::isfinite(r.hi)) {
    out = fmt::format("{} {}", r.lo_open ? ">" : "≥", doc_number(r.lo));
    if (!unit.empty() && r.lo != 0.0) out += " " + unit;
  } else {
    out = fmt::format("in {}{}, {}{}", r.lo_open ? "(" : "[", doc_number(r.lo), doc_number(r.hi),
                      r.hi_open ? ")" : "]");
    if (!unit.empty()) out += " " + unit;
  }
  if (r.also == r.also) out += fmt::format(", or {}", doc_number(r.also));
  return out;
}

namespace {

// The names a string key accepts, in a box of either dimension: "`fcc`, `sc`, ...".
std::string choices_text(const KeyDecl& d) {
  std::vector<std::string_view> names = d.choices(3);
  for (const std::string_view name : d.choices(2))
    if (std::find(names.begin(), names.end(), name) == names.end()) names.push_back(name);
  std::string out;
  for (const std::string_view name : names)
    out += fmt::format("{}`{}`", out.empty() ? "" : ", ", name);
  return out;
}

}  // namespace

std::string keys_text() {
  std::string out;
  for (const DeclaredKey& k : declared_keys()) {
    if (k.decl == nullptr) continue;
    const KeyDecl& d = *k.decl;
    out += fmt::format("{}  {}  default {}", k.path, type_text(d), default_text(k));
    if (!range_text(d).empty()) out += fmt::format("  {}", range_text(d));
    if (!d.unit.empty()) out += fmt::format("  [{}]", d.unit);
    out += fmt::format("  {}", d.doc);
    if (d.choices != nullptr) out += ": " + choices_text(d);
    out += "\n";
  }
  return out;
}

std::string keys_markdown() {
  std::string out =
      "| Key | Type | Default | Range | Unit | Meaning |\n|---|---|---|---|---|---|\n";
  for (const DeclaredKey& k : declared_keys()) {
    if (k.decl == nullptr) continue;
    const KeyDecl& d = *k.decl;
    out += fmt::format("| `{}` | {} | {} | {} | {} | {}{} |\n", k.path, type_text(d),
                       default_text(k), range_text(d), d.unit, d.doc,
                       d.choices != nullptr ? ": " + choices_text(d) : std::string());
  }
  return out;
}

}  // namespace kairos
