#include "sweep/sweep_results.hpp"

#include <algorithm>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

#include <fmt/format.h>

#include "core/error.hpp"
#include "io/atomic_file.hpp"
#include "run/output_directory.hpp"

namespace kairos {
namespace {

namespace fs = std::filesystem;

bool is_final(const std::string& stop_reason) {
  return stop_reason == "completed" || stop_reason == "at_rest" || stop_reason == "no_more_events";
}

bool is_failure(const std::string& stop_reason) {
  return stop_reason == "error" || stop_reason == "frozen_clock" || stop_reason == "write_failed";
}

// The last error line of the console's last attempt ("" if none).
std::string last_console_error(const fs::path& console) {
  constexpr std::string_view kAttempt = "kairos sweep: attempt";
  std::ifstream in(console);
  std::string line, error;
  while (std::getline(in, line)) {
    if (line.starts_with(kAttempt)) error.clear();
    for (const std::string_view prefix : {"kairos: error: ", "kairos sweep: error: "}) {
      if (line.starts_with(prefix)) error = line.substr(prefix.size());
    }
  }
  return error;
}

std::string cell_text(const nlohmann::json& v) {
  if (v.is_null()) return "nan";
  if (v.is_string()) {
    std::string s = v.get<std::string>();
    for (char& c : s) {
      if (c == '\t' || c == '\n' || c == '\r') c = ' ';
    }
    return s;
  }
  return v.dump();
}

void flatten(const nlohmann::json& v, const std::string& prefix,
             std::vector<std::pair<std::string, std::string>>& out) {
  if (v.is_object()) {
    for (auto it = v.begin(); it != v.end(); ++it) {
      flatten(it.value(), prefix.empty() ? it.key() : prefix + "." + it.key(), out);
    }
  } else if (v.is_array()) {
    const bool strings =
        !v.empty() && std::all_of(v.begin(), v.end(), [](const auto& e) { return e.is_string(); });
    if (strings || v.empty()) {
      std::string joined;
      for (const auto& e : v) {
        if (!joined.empty()) joined += ',';
        joined += cell_text(e);
      }
      out.emplace_back(prefix, joined);
    } else {
      for (std::size_t i = 0; i < v.size(); ++i) {
        flatten(v[i], prefix + "." + std::to_string(i), out);
      }
    }
  } else {
    out.emplace_back(prefix, cell_text(v));
  }
}

// A swept value as JSON: a number, boolean or quoted string that JSON reads alike, else the
// text as it was given.
nlohmann::json typed_value(const std::string& text) {
  nlohmann::json v = nlohmann::json::parse(text, nullptr, /*allow_exceptions=*/false);
  if (v.is_discarded() || !(v.is_number() || v.is_boolean() || v.is_string())) return text;
  return v;
}

}  // namespace

const char* state_name(SweepRunState state) {
  switch (state) {
    case SweepRunState::kNotRun:
      return "not_run";
    case SweepRunState::kFinished:
      return "finished";
    case SweepRunState::kStopped:
      return "stopped";
    case SweepRunState::kFailed:
      return "failed";
  }
  return "?";
}

SweepRunRecord read_sweep_run(const fs::path& dir) {
  SweepRunRecord r;
  std::error_code ec;
  r.has_restart = fs::is_regular_file(dir / kRestartFileName, ec);
  const fs::path summary = dir / kSummaryFileName;
  if (fs::is_regular_file(summary, ec)) {
    std::ifstream in(summary);
    r.summary = nlohmann::json::parse(in, nullptr, /*allow_exceptions=*/false);
    if (r.summary.is_discarded()) r.summary = nullptr;
  }
  const std::string console_error = last_console_error(dir / kSweepConsoleFile);
  const std::string reason =
      r.summary.is_object() ? r.summary.value("stop_reason", std::string()) : std::string();
  if (is_final(reason)) {
    r.state = SweepRunState::kFinished;
  } else if (is_failure(reason)) {
    r.state = SweepRunState::kFailed;
    r.error = r.summary.value("error", console_error);
  } else if (!console_error.empty()) {
    r.state = SweepRunState::kFailed;
    r.error = console_error;
  } else if (!reason.empty() || r.has_restart) {
    r.state = SweepRunState::kStopped;
  } else {
    r.state = SweepRunState::kNotRun;
  }
  return r;
}

std::vector<std::pair<std::string, std::string>> flattened_summary(const nlohmann::json& summary) {
  std::vector<std::pair<std::string, std::string>> out;
  if (summary.is_object()) flatten(summary, "", out);
  return out;
}

std::vector<SweepRunState> write_sweep_results(const fs::path& sweep_directory,
                                               const std::vector<SweepAxis>& axes,
                                               const std::vector<SweepPoint>& points) {
  std::vector<SweepRunRecord> records;
  std::vector<std::map<std::string, std::string>> rows;
  std::set<std::string> columns;
  for (const SweepPoint& p : points) {
    records.push_back(read_sweep_run(sweep_directory / p.name));
    auto& row = rows.emplace_back();
    for (auto& [key, value] : flattened_summary(records.back().summary)) {
      if (key == "error") continue;  // the table's own error column holds it
      columns.insert(key);
      row[key] = std::move(value);
    }
  }
  std::ostringstream tsv;
  tsv << "run\tdirectory\tstate\terror";
  for (const SweepAxis& axis : axes) tsv << '\t' << axis.key;
  for (const std::string& c : columns) tsv << '\t' << c;
  tsv << '\n';
  nlohmann::json runs = nlohmann::json::array();
  for (std::size_t i = 0; i < points.size(); ++i) {
    const SweepPoint& p = points[i];
    const SweepRunRecord& r = records[i];
    tsv << p.index << '\t' << p.name << '\t' << state_name(r.state) << '\t'
        << cell_text(nlohmann::json(r.error));
    for (const std::string& v : p.values) tsv << '\t' << cell_text(nlohmann::json(v));
    for (const std::string& c : columns) {
      const auto it = rows[i].find(c);
      tsv << '\t' << (it == rows[i].end() ? std::string() : it->second);
    }
    tsv << '\n';
    nlohmann::json values = nlohmann::json::object();
    for (std::size_t a = 0; a < axes.size(); ++a) values[axes[a].key] = typed_value(p.values[a]);
    runs.push_back({{"run", p.index},
                    {"directory", p.name},
                    {"state", state_name(r.state)},
                    {"error", r.error},
                    {"values", values},
                    {"summary", r.summary}});
  }
  nlohmann::json varied = nlohmann::json::array();
  for (const SweepAxis& axis : axes) {
    varied.push_back({{"key", axis.key}, {"values", axis.values}, {"spec", axis.spec}});
  }
  write_text_atomically(sweep_directory / "results.tsv", tsv.str());
  write_text_atomically(sweep_directory / "results.json",
                        nlohmann::json{{"vary", varied}, {"runs", runs}}.dump(2) + "\n");
  std::vector<SweepRunState> states;
  for (const SweepRunRecord& r : records) states.push_back(r.state);
  return states;
}

}  // namespace kairos
