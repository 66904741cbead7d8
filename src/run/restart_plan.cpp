#include "run/restart_plan.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <sstream>
#include <string_view>

#include <fmt/format.h>
#include <toml++/toml.h>

#include "core/error.hpp"
#include "run/environment_setup.hpp"

namespace kairos {

namespace {

using Flat = std::map<std::string, std::string>;

// Every leaf of a TOML tree under its dotted path, arrays of tables by index (wall[2].face),
// other arrays as one value.
void flatten(const toml::node& node, const std::string& path, Flat& out) {
  if (const toml::table* t = node.as_table()) {
    for (auto&& [key, value] : *t)
      flatten(value, path.empty() ? std::string(key.str()) : path + "." + std::string(key.str()),
              out);
    return;
  }
  if (const toml::array* a = node.as_array();
      a != nullptr && !a->empty() && a->is_array_of_tables()) {
    for (std::size_t k = 0; k < a->size(); ++k)
      flatten(*a->get(k), fmt::format("{}[{}]", path, k), out);
    return;
  }
  std::ostringstream text;
  node.visit([&](auto&& leaf) { text << leaf; });
  out[path] = text.str();
}

Flat flat_config(const Config& config) {
  Flat out;
  flatten(toml::parse(to_toml(config)), "", out);
  return out;
}

enum class Effect { kResume, kRepredict, kIgnore, kRefuse };

// The key without its array indices: boundary.wall[2].restitution -> boundary.wall.restitution.
std::string generic(const std::string& key) {
  std::string out;
  for (std::size_t k = 0; k < key.size(); ++k) {
    if (key[k] == '[') {
      std::size_t e = k + 1;
      while (e < key.size() && key[e] >= '0' && key[e] <= '9') ++e;
      if (e > k + 1 && e < key.size() && key[e] == ']') {
        k = e;  // skip "[digits]"
        continue;
      }
    }
    out += key[k];
  }
  return out;
}

bool starts_with(std::string_view s, std::string_view prefix) {
  return s.substr(0, prefix.size()) == prefix;
}

// The contact law of a wall: how a collision ends, never when it happens.
constexpr std::array<std::string_view, 7> kWallLaw = {
    "restitution",        "restitution_model",      "restitution_speed",
    "restitution_table",  "tangential_restitution", "friction",
    "elastic_below_speed"};

Effect effect_of(const std::string& key) {
  const std::string k = generic(key);
  // Compression builds a fresh start; a continued run does not compress again.
  if (starts_with(k, "compress.")) return Effect::kIgnore;
  if (k == "system.dimension") return Effect::kRefuse;
  if (starts_with(k, "system.species.")) {
    if (k == "system.species.inertia_factor") return Effect::kResume;  // a contact law's
    if (k == "system.species.fraction") return Effect::kIgnore;
    return Effect::kRefuse;  // name, diameter, mass: the particles as stored
  }
  if (starts_with(k, "system.")) return Effect::kIgnore;
  if (starts_with(k, "run.") || starts_with(k, "output.") || starts_with(k, "driving.") ||
      starts_with(k, "analysis."))
    return Effect::kResume;
  if (k == "contact.sleep_speed") return Effect::kRepredict;  // sleepers predict nothing
  if (starts_with(k, "contact.")) return Effect::kResume;
  // A wall's or a surface table's contact law resumes; its place and motion re-predict (a
  // plane moved into the particles is refused by the start checks, naming the particle).
  std::vector<std::string> tables = {"boundary.wall."};
  SurfaceTables::each([&](auto table) {
    tables.push_back(fmt::format("boundary.{}.", decltype(table)::type::key));
  });
  for (const std::string_view table : tables) {
    if (!starts_with(k, table)) continue;
    const std::string_view leaf = std::string_view(k).substr(table.size());
    if (std::find(kWallLaw.begin(), kWallLaw.end(), leaf) != kWallLaw.end()) return Effect::kResume;
    return Effect::kRepredict;
  }
  // Where and how an outlet puts particles back decides what happens at a pass, not when.
  if (starts_with(k, "boundary.outlet.insert_") || k == "boundary.outlet.seed")
    return Effect::kResume;
  // The maps' tables and their cache decide how a future contact ends, not when.
  if (k == "soft.table_cache" || k == "soft.tables" || k == "soft.table_tolerance")
    return Effect::kResume;
  return Effect::kRepredict;  // field, boundary, potential, bond, soft laws; anything new
}

// The shortest part of `key` (a table, or an element of an array of tables) that `other` does
// not hold at all: what was added or removed as a whole ("soft", "boundary.wall[2]").
std::string whole_part(const std::string& key, const Flat& other) {
  const auto held = [&](const std::string& part) {
    return std::any_of(other.begin(), other.end(), [&](const auto& kv) {
      return kv.first == part || kv.first.starts_with(part + ".") ||
             kv.first.starts_with(part + "[");
    });
  };
  for (std::size_t k = 0; k < key.size(); ++k) {
    if (key[k] != '.' && key[k] != ']') continue;
    const std::string part = key.substr(0, key[k] == ']' ? k + 1 : k);
    if (!held(part)) return part;
  }
  return key;
}

// A wall whose plane the new configuration puts elsewhere at the state's time (another normal
// velocity, amplitude, frequency or phase, or a new moving wall: the plane is a function of
// the absolute time) would jump through the particles: refused, as a new shear rate is.
void check_walls_stay(const Config& before, const Config& now, double t,
                      const std::string& restart_file) {
  if (!(t > 0.0)) return;
  for (const WallConfig& w : now.boundary.walls) {
    double was = 0.0;  // a new wall starts from its face
    for (const WallConfig& old : before.boundary.walls)
      if (old.face == w.face) was = face_wall_offset(old, before.system.dimension, t);
    const double is = face_wall_offset(w, now.system.dimension, t);
    if (std::abs(is - was) <= 1e-12 * (1.0 + std::abs(was))) continue;
    throw InputError(fmt::format(
        "restart file '{}': boundary.wall (face {}) would jump at once from {:.6g} to {:.6g} "
        "(relative to its face) at t = {:.6g}: a wall's normal motion and vibration are functions "
        "of the "
        "time since t = 0, so its velocity, amplitude, frequency or phase cannot change during "
        "a run; start a new run from the state with system.initial_state = \"{}\" (its clock "
        "starts at 0)",
        restart_file, w.face, was, is, t, restart_file));
  }
}

// A face wall that gains or loses its mass on a restart would change what the state holds (the
// wall's motion) and thermo.tsv's columns: refused. Another mass or force is fine (the wall
// moves on from where the state has it).
void check_wall_masses_stay(const Config& before, const Config& now,
                            const std::string& restart_file) {
  // Its own mass, or the container's (boundary.container: the walls of its axis).
  const auto massive = [](const Config& c, const std::string& face) {
    if (!c.boundary.container.axis.empty() && face.starts_with(c.boundary.container.axis))
      return true;
    for (const WallConfig& w : c.boundary.walls)
      if (w.face == face) return w.mass > 0.0;
    return false;
  };
  const auto sprung = [](const Config& c) {
    return !c.boundary.container.axis.empty() && c.boundary.container.spring_stiffness > 0.0;
  };
  for (const char* face : {"x-", "x+", "y-", "y+", "z-", "z+"}) {
    const bool was = massive(before, face), is = massive(now, face);
    if (was == is) continue;
    throw InputError(fmt::format(
        "restart file '{}': the wall on face {} {} mass (boundary.wall.mass or "
        "boundary.container) in the run that wrote it and {} now: a wall cannot gain or lose "
        "its mass during a run (its motion is part of the state, and thermo.tsv's columns "
        "would change); start a new run from the state with system.initial_state = \"{}\" "
        "(its walls then start on their faces: grains that a moved wall holds beyond its face "
        "make that start fail)",
        restart_file, face, was ? "had" : "had no", is ? "has" : "has none", restart_file));
  }
  const auto described = [&](const Config& c) {
    return c.boundary.container.axis.empty()
               ? std::string("none")
               : fmt::format("along {}{}", c.boundary.container.axis,
                             sprung(c) ? " on a spring" : " without a spring");
  };
  if (before.boundary.container.axis != now.boundary.container.axis ||
      sprung(before) != sprung(now)) {
    throw InputError(fmt::format(
        "restart file '{}': boundary.container was {} in the run that wrote it and is {} now: a "
        "container cannot change its axis, or gain or lose its spring, during a run "
        "(thermo.tsv's columns would change); start a new run from the state with "
        "system.initial_state = \"{}\" (its walls then start on their faces: grains that a "
        "moved container holds beyond them make that start fail)",
        restart_file, described(before), described(now), restart_file));
  }
}

}  // namespace

RestartPlan plan_restart(const Config& now, const std::string& stored, bool contacts_in_progress,
                         double before_time, const std::string& restart_file) {
  RestartPlan plan;
  plan.used = now;
  if (stored.empty()) {
    // An older file: what it was run with is unknown, so every event is predicted afresh
    // (plan_continuation infers the field its trajectories followed). Contacts in progress
    // cannot be predicted afresh: those states resume as they are.
    plan.repredict = !contacts_in_progress;
    return plan;
  }
  Config before;
  try {
    before = parse_config(stored, restart_file + " (its kairos/run/config)");
  } catch (const InputError& e) {
    throw InputError(fmt::format("restart file '{}': its stored configuration does not read: {}",
                                 restart_file, e.what()));
  }
  plan.stored_config = true;
  plan.stored_gravity = before.field.gravity;
  plan.used.system = before.system;  // the values that made the state
  const Flat a = flat_config(before), b = flat_config(now);
  std::vector<std::string> keys;
  for (const auto& [key, value] : a)
    if (auto it = b.find(key); it == b.end() || it->second != value) keys.push_back(key);
  for (const auto& [key, value] : b)
    if (!a.contains(key)) keys.push_back(key);
  std::sort(keys.begin(), keys.end());
  check_walls_stay(before, now, before_time, restart_file);
  check_wall_masses_stay(before, now, restart_file);
  for (const std::string& key : keys) {
    const auto was = a.find(key), is = b.find(key);
    const std::string from = was == a.end() ? "absent" : was->second;
    const std::string to = is == b.end() ? "absent" : is->second;
    // The Lees-Edwards offset runs from t = 0 (shear_rate * L_y * t): another rate would
    // displace the images at once by the difference.
    if (generic(key) == "boundary.shear_rate" && before_time > 0.0) {
      throw InputError(fmt::format(
          "restart file '{}': boundary.shear_rate was {} and is now {}: the Lees-Edwards images "
          "are displaced by shear_rate * L_y * t from t = 0, so a new rate at t = {} would move "
          "them at once; start a new run from the state with system.initial_state = \"{}\" "
          "(its clock starts at 0)",
          restart_file, from, to, before_time, restart_file));
    }
    switch (effect_of(key)) {
      case Effect::kRefuse:
        throw InputError(fmt::format(
            "restart file '{}': {} was {} and is now {}: a restart continues the particles as "
            "they are stored (sizes, masses, species); to change them start a new run from the "
            "state with system.initial_state = \"{}\"",
            restart_file, key, from, to, restart_file));
      case Effect::kIgnore:
        plan.ignored.push_back(key);
        break;
      case Effect::kResume:
        plan.resumed.push_back(key);
        break;
      case Effect::kRepredict:
        if (contacts_in_progress) {
          throw InputError(fmt::format(
              "restart file '{}': {} was {} and is now {}, but the state holds soft contacts "
              "in progress whose end was computed under the old physics; continue it "
              "unchanged, or start a new run from its state with system.initial_state",
              restart_file, key, from, to));
        }
        // A table added or removed (a wall, a potential, [soft]) is named once, not key by
        // key.
        {
          const std::string part = was == a.end()  ? whole_part(key, a)
                                   : is == b.end() ? whole_part(key, b)
                                                   : key;
          if (std::find(plan.changed.begin(), plan.changed.end(), part) == plan.changed.end())
            plan.changed.push_back(part);
        }
        plan.repredict = true;
        break;
    }
  }
  return plan;
}

std::string describe_restart(const RestartPlan& plan, const std::string& restart_file) {
  const auto list = [](const std::vector<std::string>& keys) {
    std::string out;
    for (std::size_t k = 0; k < keys.size() && k < 8; ++k) out += (k ? ", " : "") + keys[k];
    if (keys.size() > 8) out += fmt::format(" and {} more", keys.size() - 8);
    return out;
  };
  std::string text;
  if (!plan.stored_config) {
    if (plan.repredict) {
      return fmt::format(
          "'{}' was written by an older Kairos and does not record its configuration: every "
          "event is predicted afresh from the restored state under this configuration (not "
          "bit-identical to the run that wrote it)",
          restart_file);
    }
    return fmt::format(
        "'{}' was written by an older Kairos, does not record its configuration and holds soft "
        "contacts in progress: its predictions are resumed as they are, which is right only if "
        "the physics keys are unchanged",
        restart_file);
  }
  if (plan.repredict) {
    text = fmt::format(
        "continued with new physics ({} changed): every event is predicted afresh from the "
        "restored state; not bit-identical to a run that had it from the start",
        list(plan.changed));
  }
  if (!plan.ignored.empty()) {
    text += fmt::format(
        "{}{} not used: a restart continues the stored state (config.toml records "
        "the values that made it)",
        text.empty() ? "" : "; ", list(plan.ignored));
  }
  return text;
}

}  // namespace kairos
