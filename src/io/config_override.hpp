// `--set key=value`: one override applied to the parsed TOML tree before it is read.
// Internal to src/io (io/config.hpp describes the syntax).
#pragma once

#include <toml++/toml.h>

#include <string>

namespace kairos::config_detail {

struct AppliedOverride {
  std::string label;  // "override 'system.particles=4000'"
  std::string path;   // canonical dotted path, e.g. "system.species[0].diameter"
};

// Applies `text` ("system.species.0.diameter=1.4") to `root`: the key must be declared
// (io/config_keys.hpp); the value is TOML if it parses as one, else the text as a string (a
// string key takes the text unless it is a quoted TOML string). InputError naming the override.
AppliedOverride apply_override(toml::table& root, const std::string& text);

}  // namespace kairos::config_detail
