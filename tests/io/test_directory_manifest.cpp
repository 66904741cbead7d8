// io/directory_manifest: a directory's manifest is read or refused by name, and a command that
// asks for something else is refused naming the first entry that differs and what it was.
#include "io/directory_manifest.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "core/error.hpp"

namespace kairos {
namespace {

namespace fs = std::filesystem;

std::string refusal(const nlohmann::json& have, const nlohmann::json& want,
                    const std::vector<ManifestField>& fields) {
  try {
    require_same_manifest(have, want, fields, "runs", "sweep");
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(DirectoryManifest, AManifestThatIsNotOneIsRefusedByItsPath) {
  const fs::path dir = fs::temp_directory_path() / "kairos-test-manifest";
  fs::create_directories(dir);
  const fs::path path = dir / "sweep.json";
  for (const char* text : {"{not json", "[1, 2]", "{\"other\": 1}"}) {
    std::ofstream(path) << text;
    try {
      (void)read_manifest(path, "replica-exchange", "kairos_replica_exchange");
      ADD_FAILURE() << text << " was taken for a manifest";
    } catch (const InputError& e) {
      EXPECT_EQ(std::string(e.what()), path.string() + ": not a replica-exchange manifest");
    }
  }
  // Without a marker, any object is one.
  EXPECT_EQ(read_manifest(path, "sweep").at("other"), 1);
  fs::remove_all(dir);
}

TEST(DirectoryManifest, TheFirstEntryThatDiffersIsNamedWithWhatItWas) {
  const nlohmann::json want = {{"config_text", "a"}, {"set", {"x=1"}}, {"interval", 2.0}};
  const std::vector<ManifestField> fields = {
      {"config_text", "config text",
       [](const nlohmann::json& had) { return had.value("config", std::string("?")); }, nullptr},
      {"set", "--set list", {}, nlohmann::json::array()},
      {"interval", "interval", {}, nullptr}};
  EXPECT_EQ(refusal(want, want, fields), "");
  nlohmann::json have = want;
  have["interval"] = 3.0;
  have["set"] = nlohmann::json::array({"x=2"});
  EXPECT_EQ(refusal(have, want, fields),
            "runs holds another sweep: its --set list differs ([\"x=2\"]); continue it with the "
            "command that began it, or give another directory");
  have = want;
  have["config_text"] = "b";
  have["config"] = "old.toml";
  EXPECT_NE(refusal(have, want, fields).find("its config text differs (old.toml)"),
            std::string::npos);
  // An entry the manifest lacks takes its `absent` value: an empty --set list matches [].
  nlohmann::json bare = {{"config_text", "a"}, {"interval", 2.0}};
  EXPECT_NE(refusal(bare, want, fields).find("--set list differs ([])"), std::string::npos);
  nlohmann::json empty_set = want;
  empty_set["set"] = nlohmann::json::array();
  EXPECT_EQ(refusal(bare, empty_set, fields), "");
  bare.erase("interval");
  EXPECT_NE(refusal(bare, empty_set, fields).find("its interval differs (null)"),
            std::string::npos);
}

}  // namespace
}  // namespace kairos
