#include "sweep/sweep_grid.hpp"

#include <charconv>
#include <cmath>
#include <set>

#include <fmt/format.h>

#include "core/error.hpp"

namespace kairos {
namespace {

constexpr std::size_t kMaxRuns = 1'000'000;
constexpr std::size_t kMaxNameValue = 32;  // characters of a key or value in a directory name

std::string trimmed(const std::string& s) {
  const auto first = s.find_first_not_of(" \t");
  if (first == std::string::npos) return {};
  return s.substr(first, s.find_last_not_of(" \t") - first + 1);
}

// The whole text as a number of type T, or false.
template <typename T>
bool parse_number(const std::string& text, T& out) {
  const std::string t = trimmed(text);
  if (t.empty()) return false;
  const char* begin = t.data();
  if (*begin == '+') ++begin;
  const auto [end, ec] = std::from_chars(begin, t.data() + t.size(), out);
  return ec == std::errc() && end == t.data() + t.size();
}

// Splits at commas outside brackets, braces and quotes (a TOML array is one value).
std::vector<std::string> split_list(const std::string& text) {
  std::vector<std::string> parts(1);
  int depth = 0;
  char quote = 0;
  for (const char c : text) {
    if (quote != 0) {
      if (c == quote) quote = 0;
    } else if (c == '"' || c == '\'') {
      quote = c;
    } else if (c == '[' || c == '{') {
      ++depth;
    } else if ((c == ']' || c == '}') && depth > 0) {
      --depth;
    } else if (c == ',' && depth == 0) {
      parts.emplace_back();
      continue;
    }
    parts.back() += c;
  }
  for (std::string& p : parts) p = trimmed(p);
  return parts;
}

// 12 significant digits: A:B:N's 0.1:0.5:9 gives 0.15, not 0.15000000000000002.
std::string number_text(double x) {
  return fmt::format("{:.12g}", x);
}

std::vector<std::string> spaced_values(const std::string& arg, const std::vector<std::string>& f) {
  double a = 0.0, b = 0.0;
  long long n = 0;
  const bool log = f.size() == 4;
  if (!parse_number(f[0], a) || !parse_number(f[1], b) || !std::isfinite(a) || !std::isfinite(b)) {
    throw InputError(fmt::format("{}: A and B of A:B:N must be finite numbers", arg));
  }
  if (!parse_number(f[2], n) || n < 1) {
    throw InputError(fmt::format("{}: N of A:B:N must be an integer >= 1", arg));
  }
  if (static_cast<std::size_t>(n) > kMaxRuns) {
    throw InputError(
        fmt::format("{}: N = {} values is more than a sweep takes ({})", arg, n, kMaxRuns));
  }
  if (log && f[3] != "log") {
    throw InputError(fmt::format("{}: the fourth field of A:B:N:log must be 'log'", arg));
  }
  if (log && (a <= 0.0 || b <= 0.0)) {
    throw InputError(fmt::format("{}: A:B:N:log needs A > 0 and B > 0", arg));
  }
  std::vector<std::string> values;
  for (long long i = 0; i < n; ++i) {
    const double s = n == 1 ? 0.0 : static_cast<double>(i) / static_cast<double>(n - 1);
    const double x =
        log ? std::exp(std::log(a) + s * (std::log(b) - std::log(a))) : a + s * (b - a);
    values.push_back(number_text(n > 1 && i == n - 1 ? b : x));  // B exactly as given
  }
  return values;
}

std::vector<std::string> integer_values(const std::string& arg, const std::string& spec,
                                        std::size_t dots) {
  long long i = 0, j = 0;
  if (!parse_number(spec.substr(0, dots), i) || !parse_number(spec.substr(dots + 2), j)) {
    throw InputError(fmt::format("{}: I..J needs two integers", arg));
  }
  if (i > j) throw InputError(fmt::format("{}: I..J needs I <= J", arg));
  if (static_cast<unsigned long long>(j - i) >= kMaxRuns) {
    throw InputError(
        fmt::format("{}: {}..{} is more values than a sweep takes ({})", arg, i, j, kMaxRuns));
  }
  std::vector<std::string> values;
  for (long long k = i; k <= j; ++k) values.push_back(std::to_string(k));
  return values;
}

std::string name_part(const std::string& text) {
  std::string out;
  for (const char c : text.substr(0, kMaxNameValue)) {
    const bool plain = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
                       c == '.' || c == '_' || c == '+' || c == '-' || c == '=';
    out += plain ? c : '_';
  }
  return out;
}

// "system.species.0.diameter" -> "diameter"; the full key when two axes share the last part.
std::vector<std::string> short_keys(const std::vector<SweepAxis>& axes) {
  std::vector<std::string> names;
  for (const SweepAxis& axis : axes) {
    const auto dot = axis.key.find_last_of('.');
    names.push_back(dot == std::string::npos ? axis.key : axis.key.substr(dot + 1));
  }
  std::vector<std::string> unique = names;
  for (std::size_t a = 0; a < axes.size(); ++a) {
    for (std::size_t b = 0; b < axes.size(); ++b) {
      if (a != b && names[a] == names[b]) unique[a] = axes[a].key;
    }
  }
  return unique;
}

}  // namespace

SweepAxis parse_sweep_axis(const std::string& text, const std::string& option) {
  const std::string arg = option + " " + text;
  const auto eq = text.find('=');
  if (eq == std::string::npos || eq == 0) {
    throw InputError(
        fmt::format("{}: expected KEY=VALUES (e.g. "
                    "system.packing_fraction=0.1:0.5:9 or system.seed=1..10)",
                    arg));
  }
  SweepAxis axis;
  axis.key = trimmed(text.substr(0, eq));
  axis.spec = trimmed(text.substr(eq + 1));
  if (axis.spec.empty()) throw InputError(fmt::format("{}: no values", arg));
  const bool has_structure = axis.spec.find_first_of("[{\"'") != std::string::npos;
  const auto dots = axis.spec.find("..");
  if (!has_structure && dots != std::string::npos && axis.spec.find(',') == std::string::npos) {
    axis.values = integer_values(arg, axis.spec, dots);
  } else if (!has_structure && axis.spec.find(':') != std::string::npos &&
             axis.spec.find(',') == std::string::npos) {
    const std::vector<std::string> fields = [&] {
      std::vector<std::string> f(1);
      for (const char c : axis.spec) {
        if (c == ':') {
          f.emplace_back();
        } else {
          f.back() += c;
        }
      }
      return f;
    }();
    if (fields.size() != 3 && fields.size() != 4) {
      throw InputError(fmt::format("{}: expected A:B:N or A:B:N:log", arg));
    }
    axis.values = spaced_values(arg, fields);
  } else {
    axis.values = split_list(axis.spec);
    for (const std::string& v : axis.values) {
      if (v.empty()) throw InputError(fmt::format("{}: an empty value in the list", arg));
    }
  }
  // Two runs of the same values under two names would count twice in every average.
  std::set<std::string> seen;
  for (const std::string& v : axis.values) {
    if (!seen.insert(v).second) {
      throw InputError(
          fmt::format("{}: the value {} comes twice (as written, or at 12 "
                      "significant digits)",
                      arg, v));
    }
  }
  return axis;
}

std::vector<SweepPoint> sweep_points(const std::vector<SweepAxis>& axes) {
  if (axes.empty()) throw InputError("kairos sweep: give at least one --vary KEY=VALUES");
  std::set<std::string> keys;
  std::size_t count = 1;
  for (const SweepAxis& axis : axes) {
    if (!keys.insert(axis.key).second) {
      throw InputError(fmt::format("--vary: the key {} is varied twice", axis.key));
    }
    count *= axis.values.size();
    if (count > kMaxRuns) {
      throw InputError(
          fmt::format("--vary: the grid has more runs than a sweep takes ({})", kMaxRuns));
    }
  }
  const std::vector<std::string> names = short_keys(axes);
  const int digits = std::max(4, static_cast<int>(std::to_string(count - 1).size()));
  std::vector<SweepPoint> points(count);
  for (std::size_t i = 0; i < count; ++i) {
    SweepPoint& p = points[i];
    p.index = i;
    p.values.resize(axes.size());
    std::size_t rest = i;
    for (std::size_t a = axes.size(); a-- > 0;) {
      p.values[a] = axes[a].values[rest % axes[a].values.size()];
      rest /= axes[a].values.size();
    }
    p.name = fmt::format("{:0{}}", i, digits);
    for (std::size_t a = 0; a < axes.size(); ++a) {
      p.name += fmt::format("_{}={}", name_part(names[a]), name_part(p.values[a]));
    }
  }
  return points;
}

std::vector<std::string> point_overrides(const std::vector<SweepAxis>& axes,
                                         const SweepPoint& point) {
  std::vector<std::string> out;
  for (std::size_t a = 0; a < axes.size(); ++a) out.push_back(axes[a].key + "=" + point.values[a]);
  return out;
}

}  // namespace kairos
