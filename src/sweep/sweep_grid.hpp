// The grid of a parameter sweep (`kairos sweep`, docs/sweeps.md): each `--vary KEY=VALUES` is
// one axis, the runs are every combination of one value per axis (the first axis varies
// slowest, as nested loops in the order given), and each run is `kairos run CONFIG` with its
// values as `--set KEY=VALUE` overrides after the sweep's own `--set`s.
//
// VALUES is one of
//   A:B:N       N numbers evenly spaced from A to B, both included (N >= 1);
//   A:B:N:log   N numbers spaced evenly in log from A to B (both > 0);
//   I..J        the integers from I to J, both included (I <= J);
//   V1,V2,...   the values as written (TOML values, as --set takes them; a single value too).
#pragma once

#include <cstddef>
#include <string>
#include <vector>

namespace kairos {

struct SweepAxis {
  std::string key;                  // dotted config key, as --set names it
  std::string spec;                 // VALUES as written
  std::vector<std::string> values;  // each as passed to --set (numbers in shortest form)
};

struct SweepPoint {
  std::size_t index = 0;            // 0-based, in grid order
  std::vector<std::string> values;  // one per axis
  std::string name;                 // its directory's name, unique in the sweep
};

// "KEY=VALUES" as above; InputError naming the argument (after `option`, the command-line
// option that gave it) for a malformed one.
SweepAxis parse_sweep_axis(const std::string& text, const std::string& option = "--vary");

// Every combination, in grid order, named "NNNN_key=value_..." (the key's last part; a name
// character outside [A-Za-z0-9._+=-] becomes '_'). InputError for no axis, a key varied twice,
// or more than 10^6 runs.
std::vector<SweepPoint> sweep_points(const std::vector<SweepAxis>& axes);

// The point's values as --set arguments ("key=value"), in axis order.
std::vector<std::string> point_overrides(const std::vector<SweepAxis>& axes,
                                         const SweepPoint& point);

}  // namespace kairos
