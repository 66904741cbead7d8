// The declarations of the config keys (io/config_keys.hpp): every key reads, overrides and
// writes back; a value out of its range is refused naming the key; docs/config.md documents
// exactly the declared keys with their declared type, default, range and choices.
#include "io/config_keys.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

#include <fmt/format.h>

#include "core/error.hpp"
#include "io/config.hpp"

namespace kairos {
namespace {

constexpr std::string_view kMinimal = "[system]\nparticles = 500\npacking_fraction = 0.3\n";

// A config that uses every table: [soft] and [[potential]] exclude each other, so two.
constexpr std::string_view kEveryTableHard = R"([system]
particles = 500
packing_fraction = 0.3
chain_length = 5

[[system.species]]
name = "A"

[[system.species]]
name = "B"

[[potential]]
kind = "square_well"

[[potential]]
species = ["A", "B"]
kind = "spring_dashpot"
stiffness = 1e4
length = 1.1

[[bond]]
kind = "tether"
max_length = 1.5

[[contact.pair]]
species = ["A", "B"]
restitution = 0.8

[[boundary.wall]]
face = "z-"

[[boundary.wall]]
face = "z+"

[[boundary.plane]]
normal = [0.0, 1.0, 1.0]
point = [0.0, 0.0, 0.5]

[[boundary.cylinder]]
axis = "x"
center = [0.0, 2.0, 2.0]
radius = 1.0

[[boundary.sphere]]
center = [3.0, 2.0, 2.0]
radius = 1.0

[driving]
kind = "andersen"
)";

constexpr std::string_view kEveryTableSoft = R"([system]
particles = 500
packing_fraction = 0.3

[[system.species]]
name = "A"

[[system.species]]
name = "B"

[soft]
model = "hertz"
young = 1e5
restitution = 0.9

[[soft.pair]]
species = ["A", "B"]
model = "dashpot"
stiffness = 1e4

[run]
integrator = "dem"
)";

// The path of a declared key in the configs above: "[]" -> "[0]" (potential[1] is the
// spring_dashpot).
std::string concrete(const std::string& path) {
  std::string out = path;
  const std::string_view last = std::string_view(path).substr(path.rfind('.') + 1);
  if (path.starts_with("potential[]") &&
      (last == "restitution" || last == "damping" || last == "force_zero")) {
    out.replace(0, 11, "potential[1]");
  }
  for (auto at = out.find("[]"); at != std::string::npos; at = out.find("[]"))
    out.replace(at, 2, "[0]");
  return out;
}

std::string base_for(const std::string& path) {
  if (path.starts_with("soft") || path == "run.time_step") return std::string(kEveryTableSoft);
  // Compression grows in a periodic box; it needs a target (two, so either may be unset).
  if (path.starts_with("compress."))
    return std::string(kMinimal) + "\n[compress]\njammed = true\npressure = 1e6\n";
  // An analysis's own keys act only with that analysis on; those of log-spaced frames with
  // them.
  const bool analysis = path.starts_with("analysis.");
  const bool log_frames =
      path == "output.trajectory_frames_per_decade" || path == "output.trajectory_log_period";
  return std::string(kEveryTableHard) +
         (analysis ? "\n[analysis]\nmsd = true\nrdf = true\nstructure_factor = true\n"
                     "bond_order = true\n"
                   : "") +
         (log_frames ? "\n[output]\ntrajectory_spacing = \"log\"\ntrajectory_interval = 0.01\n"
                     : "");
}

// A value inside the key's range (and valid with the configs above), as --set writes it.
std::string valid_value(const DeclaredKey& key) {
  const KeyDecl& d = *key.decl;
  const Range& r = d.range;
  // Keys whose values depend on others (a soft law's model, a potential's kind), the dimension
  // (the configs have walls z- and z+) and the kinds and models themselves: the tests of
  // tests/io/test_config*.cpp.
  if (r.by_rule || key.path == "system.dimension" || key.path.ends_with(".kind") ||
      key.path.ends_with(".model") || key.path == "run.integrator") {
    return "";
  }
  if (d.choices != nullptr) return std::string(d.choices(3).front());
  switch (d.type) {
    case KeyType::kInteger:
    case KeyType::kUnsigned:
      return r.bounded() ? fmt::format("{}", static_cast<long long>(std::ceil(r.lo))) : "";
    case KeyType::kFloat: {
      if (!r.bounded()) return "";
      if (std::isfinite(r.hi) && r.lo < 0.0) return "0.0";
      const double v = r.lo_open ? (std::isfinite(r.hi) ? 0.5 * (r.lo + r.hi) : r.lo + 1.0) : r.lo;
      return fmt::format("{:.17g}", v);
    }
    case KeyType::kBoolean:
      return "false";
    default:
      return "";
  }
}

TEST(ConfigKeys, EveryPathIsDeclaredOnceAndHasADocLine) {
  std::set<std::string> seen;
  for (const DeclaredKey& key : declared_keys()) {
    EXPECT_TRUE(seen.insert(key.path).second) << "declared twice: " << key.path;
    if (key.decl == nullptr) continue;
    EXPECT_FALSE(key.decl->doc.empty()) << key.path;
    EXPECT_FALSE(type_text(*key.decl).empty()) << key.path;
  }
  EXPECT_NE(find_declared("system.species[3].diameter"), nullptr);
  EXPECT_EQ(find_declared("system.species[3].diameterr"), nullptr);
}

// The member a key is stored in has the C++ type its TOML type reads into.
TEST(ConfigKeys, MembersMatchTheirTypes) {
  for (const DeclaredKey& key : declared_keys()) {
    if (key.decl == nullptr || !key.decl->member) continue;
    const CppType cpp = key.decl->member.cpp;
    switch (key.decl->type) {
      case KeyType::kInteger:
        EXPECT_TRUE(cpp == CppType::kInt || cpp == CppType::kInt64) << key.path;
        break;
      case KeyType::kUnsigned:
        EXPECT_EQ(cpp, CppType::kUint64) << key.path;
        break;
      case KeyType::kFloat:
        EXPECT_EQ(cpp, CppType::kDouble) << key.path;
        break;
      case KeyType::kString:
        EXPECT_EQ(cpp, CppType::kString) << key.path;
        break;
      case KeyType::kBoolean:
        EXPECT_EQ(cpp, CppType::kBool) << key.path;
        break;
      case KeyType::kFloats:
      case KeyType::kVector:
        EXPECT_EQ(cpp, CppType::kDoubles) << key.path;
        break;
      case KeyType::kStrings:
        EXPECT_EQ(cpp, CppType::kStrings) << key.path;
        break;
      case KeyType::kSpeedTable:
        EXPECT_EQ(cpp, CppType::kSpeedTable) << key.path;
        break;
      default:
        ADD_FAILURE() << "a table with a member: " << key.path;
    }
  }
}

// Every key with a member, set by --set to a value in its range, reads back into the Config and
// survives to_toml -> parse_config.
TEST(ConfigKeys, EveryKeySetByOverrideRoundTrips) {
  int tried = 0;
  for (const DeclaredKey& key : declared_keys()) {
    if (key.decl == nullptr || !key.decl->member) continue;
    const std::string value = valid_value(key);
    if (value.empty()) continue;
    const std::string path = concrete(key.path);
    const std::string set = path + "=" + value;
    SCOPED_TRACE(set);
    Config c;
    try {
      c = parse_config(base_for(key.path), "test.toml", {set});
    } catch (const InputError& e) {
      ADD_FAILURE() << e.what();
      continue;
    }
    ++tried;
    const std::string written = to_toml(c);
    EXPECT_EQ(parse_config(written, "config.toml"), c) << written;
  }
  EXPECT_GT(tried, 60);
}

// A value beyond the declared range is refused naming the key (the dimensionless ranges when
// the file is read; the others need the start state: tests/run/test_config_ranges.cpp).
TEST(ConfigKeys, OutOfRangeIsRefusedNamingTheKey) {
  int tried = 0;
  for (const DeclaredKey& key : declared_keys()) {
    if (key.decl == nullptr || !key.decl->member) continue;
    const Range& r = key.decl->range;
    if (r.by_rule || r.scale != Scale::kNone || !r.bounded()) continue;
    if (key.decl->type != KeyType::kFloat && key.decl->type != KeyType::kInteger) continue;
    const double beyond = std::isfinite(r.hi) ? r.hi + 1.0 + std::abs(r.hi) : r.lo - 1.0;
    const std::string value = key.decl->type == KeyType::kInteger
                                  ? fmt::format("{}", static_cast<long long>(beyond))
                                  : fmt::format("{:.17g}", beyond);
    const std::string path = concrete(key.path);
    SCOPED_TRACE(path + "=" + value);
    try {
      parse_config(base_for(key.path), "test.toml", {path + "=" + value});
      ADD_FAILURE() << "accepted";
    } catch (const InputError& e) {
      const std::string message = e.what();
      EXPECT_NE(message.find(path + ": must be"), std::string::npos) << message;
      EXPECT_NE(message.find("got"), std::string::npos) << message;
    }
    ++tried;
  }
  EXPECT_GT(tried, 20);
}

TEST(ConfigKeys, OverrideOfEveryKindOfValue) {
  const Config c = parse_config(
      kMinimal, "test.toml",
      {"system.seed=7", "system.temperature=2", "run.validate=true", "output.directory=2024",
       "field.gravity=[0, 0, -2]", "boundary.wall.0.face=z-", "boundary.wall.1.face=z+",
       "contact.restitution_model=table", "contact.restitution_table=[[0.0, 1.0], [1.0, 0.5]]"});
  EXPECT_EQ(c.system.seed, 7u);
  EXPECT_EQ(c.system.temperature, 2.0);
  EXPECT_TRUE(c.run.validate);
  EXPECT_EQ(c.output.directory, "2024");
  EXPECT_EQ(c.field.gravity, (std::vector<double>{0.0, 0.0, -2.0}));
  ASSERT_EQ(c.interactions.contact.restitution_table.size(), 2u);
  EXPECT_EQ(c.interactions.contact.restitution_table[1][1], 0.5);
}

TEST(ConfigKeys, DocNumbers) {
  EXPECT_EQ(doc_number(1e-9), "10⁻⁹");
  EXPECT_EQ(doc_number(1e15), "10¹⁵");
  EXPECT_EQ(doc_number(-1.0), "−1");
  EXPECT_EQ(doc_number(0.5), "0.5");
  EXPECT_EQ(doc_number(100000.0), "100 000");
}

// `kairos config-keys [--markdown]`: one line, or one table row, per declared key.
TEST(ConfigKeys, ListingsHaveEveryKey) {
  const std::string markdown = keys_markdown();
  const std::string text = keys_text();
  EXPECT_TRUE(markdown.starts_with("| Key | Type | Default | Range | Unit | Meaning |"));
  for (const DeclaredKey& key : declared_keys()) {
    if (key.decl == nullptr) continue;
    EXPECT_NE(markdown.find(fmt::format("| `{}` | ", key.path)), std::string::npos) << key.path;
    EXPECT_NE(text.find(key.path + "  "), std::string::npos) << key.path;
  }
  EXPECT_NE(markdown.find("| `contact.restitution` | float | `1.0` | in [0, 1] |"),
            std::string::npos);
}

// ----- docs/config.md

struct DocRow {
  std::string table;  // the declared path of the table ("system.species[]")
  std::vector<std::string> keys;
  std::string type, default_value, meaning;
  int line = 0;
};

std::vector<std::string> cells(const std::string& line) {
  // Split on '|' not escaped as "\|".
  std::vector<std::string> out;
  std::string cell;
  for (std::size_t i = 1; i < line.size(); ++i) {
    if (line[i] == '|' && line[i - 1] != '\\') {
      const auto first = cell.find_first_not_of(' ');
      const auto last = cell.find_last_not_of(' ');
      out.push_back(first == std::string::npos ? "" : cell.substr(first, last - first + 1));
      cell.clear();
    } else {
      cell += line[i];
    }
  }
  return out;
}

// The rows of every key table, each after a "<!-- keys: TABLE -->" line.
std::vector<DocRow> doc_rows() {
  std::ifstream in(std::string(KAIROS_SOURCE_DIR) + "/docs/config.md");
  EXPECT_TRUE(in) << "docs/config.md";
  std::vector<DocRow> rows;
  std::string line, table;
  int number = 0;
  bool in_table = false;
  while (std::getline(in, line)) {
    ++number;
    if (line.starts_with("<!-- keys: ")) {
      table = line.substr(11, line.find(" -->") - 11);
      in_table = false;
      continue;
    }
    if (table.empty()) continue;
    if (!line.starts_with("|")) {
      if (in_table) table.clear();
      continue;
    }
    in_table = true;
    const std::vector<std::string> c = cells(line);
    if (c.size() != 4 || c[0] == "Key" || c[0].starts_with("---")) continue;
    DocRow row{table, {}, c[1], c[2], c[3], number};
    std::stringstream names(c[0]);
    std::string name;
    while (std::getline(names, name, ',')) {
      const auto open = name.find('`'), close = name.rfind('`');
      if (open != std::string::npos && close > open)
        row.keys.push_back(name.substr(open + 1, close - open - 1));
    }
    rows.push_back(row);
  }
  return rows;
}

TEST(ConfigKeys, DocsDocumentExactlyTheDeclaredKeys) {
  std::map<std::string, int> documented;
  for (const DocRow& row : doc_rows()) {
    for (const std::string& name : row.keys) {
      const std::string path = row.table + "." + name;
      SCOPED_TRACE(fmt::format("docs/config.md:{}: {}", row.line, path));
      const DeclaredKey* key = find_declared(path);
      ASSERT_NE(key, nullptr) << "documented but not declared";
      EXPECT_TRUE(documented.emplace(path, row.line).second) << "documented twice";
      if (key->decl == nullptr) {  // a table within the table
        EXPECT_EQ(row.type, "array of tables");
        continue;
      }
      const KeyDecl& d = *key->decl;
      EXPECT_EQ(row.default_value, default_text(*key)) << "default";
      if (!key->shared_from.empty()) {
        EXPECT_EQ(row.type, "") << "a shared key's row has no type";
        continue;
      }
      EXPECT_EQ(row.keys.size(), 1u) << "one key per row";
      EXPECT_EQ(row.type, type_text(d)) << "type";
      const std::string range = range_text(d);
      if (!range.empty()) {
        EXPECT_NE(row.meaning.find(range), std::string::npos) << "range '" << range << "'";
      }
      if (d.choices != nullptr) {
        std::set<std::string_view> names;
        for (const std::string_view c : d.choices(3)) names.insert(c);
        for (const std::string_view c : d.choices(2)) names.insert(c);
        for (const std::string_view c : names) {
          EXPECT_NE(row.meaning.find(fmt::format("`{}`", c)), std::string::npos)
              << "choice '" << c << "'";
        }
      }
    }
  }
  for (const DeclaredKey& key : declared_keys()) {
    if (key.decl == nullptr) continue;
    EXPECT_TRUE(documented.count(key.path)) << "declared but not documented: " << key.path;
  }
}

}  // namespace
}  // namespace kairos
