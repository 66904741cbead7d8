// The manifest a directory of many runs keeps (a sweep's sweep.json, a replica-exchange
// ensemble's replica_exchange.json): what began it, so that a command pointed at the directory
// again continues it only when it asks for the same thing, and names what differs otherwise.
#pragma once

#include <filesystem>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

namespace kairos {

// One entry a continuation must repeat.
struct ManifestField {
  std::string key;   // in the manifest
  std::string name;  // in the message ("config text", "--set list")
  // What the directory's manifest holds, for the message (empty: its value as JSON).
  std::function<std::string(const nlohmann::json& have)> shown;
  nlohmann::json absent = nullptr;  // its value when the manifest lacks it
};

// The manifest at `path`; InputError "PATH: not a KIND manifest" when it is not a JSON object
// (or lacks `marker`, when one is given).
nlohmann::json read_manifest(const std::filesystem::path& path, std::string_view kind,
                             std::string_view marker = {});

// InputError at the first of `fields` whose value in `have` (the directory's manifest) differs
// from `want` (this command's): "DIR holds another KIND: its NAME differs (WAS); continue it
// with the command that began it, or give another directory".
void require_same_manifest(const nlohmann::json& have, const nlohmann::json& want,
                           const std::vector<ManifestField>& fields,
                           const std::filesystem::path& directory, std::string_view kind);

}  // namespace kairos
