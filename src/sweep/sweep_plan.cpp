#include "sweep/sweep_plan.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <fstream>
#include <set>
#include <sstream>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "core/error.hpp"
#include "io/atomic_file.hpp"
#include "io/config.hpp"
#include "io/directory_manifest.hpp"

namespace kairos {
namespace {

namespace fs = std::filesystem;

constexpr const char* kManifest = "sweep.json";

// The dotted key as --set canonicalises it: "system.species[0].diameter" and
// "system.species.0.diameter" name one key.
std::string canonical_key(std::string key) {
  std::string out;
  for (const char c : key) {
    if (c == '[') {
      out += '.';
    } else if (c != ']') {
      out += c;
    }
  }
  return out;
}

std::string override_key(const std::string& text) {
  return canonical_key(text.substr(0, text.find('=')));
}

nlohmann::json manifest(const SweepPlan& plan) {
  nlohmann::json axes = nlohmann::json::array();
  for (const SweepAxis& a : plan.axes) {
    axes.push_back({{"key", a.key}, {"spec", a.spec}, {"values", a.values}});
  }
  return {{"kairos_sweep", 1},
          {"config", fs::absolute(plan.config).lexically_normal().string()},
          {"config_text", plan.config_text},
          {"set", plan.overrides},
          {"vary", axes},
          {"runs", plan.points.size()}};
}

}  // namespace

std::vector<std::string> SweepPlan::run_arguments(const SweepPoint& point) const {
  std::vector<std::string> args = {"run", run_config().string(), "-o",
                                   run_directory(point).string()};
  for (const std::string& s : overrides) {
    args.push_back("--set");
    args.push_back(s);
  }
  for (const std::string& s : point_overrides(axes, point)) {
    args.push_back("--set");
    args.push_back(s);
  }
  return args;
}

SweepPlan plan_sweep(const fs::path& config, const std::vector<std::string>& overrides,
                     const std::vector<std::string>& vary, const fs::path& directory) {
  if (directory.empty()) throw InputError("-o/--output: the sweep directory must not be empty");
  SweepPlan plan;
  plan.config = config;
  plan.config_text = read_config_text(config);
  plan.overrides = overrides;
  plan.directory = directory;
  for (const std::string& v : vary) plan.axes.push_back(parse_sweep_axis(v));
  std::set<std::string> set_keys;
  for (const std::string& s : overrides) set_keys.insert(override_key(s));
  for (const SweepAxis& axis : plan.axes) {
    const std::string key = canonical_key(axis.key);
    if (key == "output.directory") {
      throw InputError(
          "--vary output.directory: each run of a sweep has its own directory "
          "(SWEEPDIR/NAME); vary something else");
    }
    if (set_keys.count(key) != 0) {
      throw InputError(fmt::format("--vary {}: the key is also given by --set; give it once", key));
    }
  }
  plan.points = sweep_points(plan.axes);
  for (const SweepPoint& p : plan.points) {
    std::vector<std::string> all = overrides;
    for (const std::string& s : point_overrides(plan.axes, p)) all.push_back(s);
    try {
      (void)parse_config(plan.config_text, config.string(), all);
    } catch (const InputError& e) {
      throw InputError(fmt::format("run {} of the sweep ({}): {}", p.index, p.name, e.what()));
    }
  }
  return plan;
}

void make_sweep_directory(const SweepPlan& plan) {
  std::error_code ec;
  fs::create_directories(plan.directory, ec);
  if (ec || !fs::is_directory(plan.directory)) {
    throw InputError(fmt::format("{}: cannot create the sweep directory: {}",
                                 plan.directory.string(), ec ? ec.message() : "not a directory"));
  }
}

void claim_sweep_directory(const SweepPlan& plan) {
  std::error_code ec;
  const fs::path path = plan.directory / kManifest;
  const nlohmann::json want = manifest(plan);
  // The copy every run reads, written again if it went missing (its text is the manifest's).
  auto write_copy = [&] {
    std::ifstream in(plan.run_config(), std::ios::binary);
    std::ostringstream have;
    have << in.rdbuf();
    if (!in || have.str() != plan.config_text) {
      write_text_atomically(plan.run_config(), plan.config_text);
    }
  };
  if (!fs::exists(path, ec)) {
    write_copy();
    write_text_atomically(path, want.dump(2) + "\n");
    return;
  }
  const nlohmann::json have = read_manifest(path, "sweep");
  const auto vary_flags = [](const nlohmann::json& had) {
    std::string was;
    for (const auto& a : had.value("vary", nlohmann::json::array())) {
      was += fmt::format("{}--vary {}={}", was.empty() ? "" : " ", a.value("key", std::string("?")),
                         a.value("spec", std::string("?")));
    }
    return was;
  };
  require_same_manifest(
      have, want,
      {{"config_text", "config text",
        [](const nlohmann::json& had) { return had.value("config", std::string("?")); }, ""},
       {"set", "--set list", {}, nlohmann::json::array()},
       {"vary", "grid", vary_flags, nlohmann::json::array()}},
      plan.directory, "sweep");
  write_copy();
}

SweepDirectoryLock::SweepDirectoryLock(const fs::path& directory) {
  const fs::path lock = directory / ".kairos-sweep.lock";
  fd_ = ::open(lock.c_str(), O_RDWR | O_CREAT, 0666);  // inherited by the runs (header)
  if (fd_ < 0) {
    throw InputError(fmt::format("{}: cannot open: {}", lock.string(), std::strerror(errno)));
  }
  if (::flock(fd_, LOCK_EX | LOCK_NB) != 0) {
    ::close(fd_);
    fd_ = -1;
    throw InputError(fmt::format("{}: in use by another sweep", directory.string()));
  }
}

SweepDirectoryLock::~SweepDirectoryLock() {
  if (fd_ >= 0) ::close(fd_);
}

}  // namespace kairos
