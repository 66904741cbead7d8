#include "run/provenance.hpp"

#include <unistd.h>

#include <array>
#include <ctime>

#include "kairos_git_commit.hpp"  // generated into the build tree (CMakeLists.txt)

namespace kairos {

namespace {

std::string utc_now() {
  const std::time_t now = std::time(nullptr);
  std::tm utc{};
  if (gmtime_r(&now, &utc) == nullptr) return "unknown";
  std::array<char, 32> text{};
  const std::size_t n = std::strftime(text.data(), text.size(), "%Y-%m-%dT%H:%M:%SZ", &utc);
  return n > 0 ? std::string(text.data(), n) : std::string("unknown");
}

std::string host_name() {
  std::array<char, 256> name{};
  if (gethostname(name.data(), name.size() - 1) != 0) return "unknown";
  return std::string(name.data());
}

// A word the shell reads back unchanged: as it is when it has only safe characters, else in
// single quotes (a single quote inside written as '\'').
std::string shell_word(const std::string& word) {
  const bool safe = !word.empty() && word.find_first_not_of(
                                         "abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ"
                                         "0123456789_-+=.,/:@%") == std::string::npos;
  if (safe) return word;
  std::string out(1, '\'');
  for (const char c : word) {
    if (c == '\'')
      out.append("'\\''");
    else
      out.push_back(c);
  }
  out.push_back('\'');
  return out;
}

}  // namespace

Provenance provenance_now(const std::string& command_line,
                          const std::optional<std::filesystem::path>& restart_file) {
  Provenance p;
  p.version = KAIROS_VERSION;
  p.commit = KAIROS_GIT_COMMIT;
  p.date = utc_now();
  p.host = host_name();
  p.command_line = command_line;
  if (restart_file) {
    std::error_code ec;
    const std::filesystem::path absolute = std::filesystem::absolute(*restart_file, ec);
    p.restart_file = (ec ? *restart_file : absolute).string();
  }
  return p;
}

nlohmann::json to_json(const Provenance& p) {
  return {{"version", p.version},
          {"commit", p.commit},
          {"date", p.date},
          {"host", p.host},
          {"command_line", p.command_line},
          {"restart_file", p.restart_file}};
}

std::string toml_comment(const Provenance& p) {
  std::string out = "# Written by kairos " + p.version + " (commit " + p.commit + ") on " + p.host +
                    ", " + p.date + ".\n";
  if (!p.command_line.empty()) out += "# Command: " + p.command_line + "\n";
  if (!p.restart_file.empty()) out += "# Continued from: " + p.restart_file + "\n";
  return out;
}

std::string shell_command_line(const std::vector<std::string>& words) {
  std::string out;
  for (const std::string& w : words) {
    if (!out.empty()) out.push_back(' ');
    out.append(shell_word(w));
  }
  return out;
}

}  // namespace kairos
