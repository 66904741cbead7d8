#include "io/directory_manifest.hpp"

#include <fstream>

#include <fmt/format.h>

#include "core/error.hpp"

namespace kairos {

nlohmann::json read_manifest(const std::filesystem::path& path, std::string_view kind,
                             std::string_view marker) {
  std::ifstream in(path);
  const nlohmann::json have = nlohmann::json::parse(in, nullptr, /*allow_exceptions=*/false);
  if (have.is_discarded() || !have.is_object() ||
      (!marker.empty() && !have.contains(std::string(marker)))) {
    throw InputError(fmt::format("{}: not a {} manifest", path.string(), kind));
  }
  return have;
}

void require_same_manifest(const nlohmann::json& have, const nlohmann::json& want,
                           const std::vector<ManifestField>& fields,
                           const std::filesystem::path& directory, std::string_view kind) {
  for (const ManifestField& field : fields) {
    const nlohmann::json& wanted = want.at(field.key);
    const nlohmann::json had = have.value(field.key, field.absent);
    if (had == wanted) continue;
    throw InputError(fmt::format(
        "{} holds another {}: its {} differs ({}); continue it with the command that began it, "
        "or give another directory",
        directory.string(), kind, field.name, field.shown ? field.shown(have) : had.dump()));
  }
}

}  // namespace kairos
