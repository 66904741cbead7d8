// `kairos table`: build, inspect and plot the lookup tables of the soft-sphere collision map
// (interactions/soft_map_table.hpp, docs/soft_tables.md).
//
//   kairos table build   --model dashpot|hertz --stiffness K --damping G
//   --reduced-mass MU
//                        --contact-distance L --min-speed V --max-speed V
//                        [--max-ratio R]
//                        [--head-on] [--tolerance T] [--cache DIR] [--threads
//                        N]
//   kairos table inspect FILE
//   kairos table plot    FILE | (the build flags)  -o DIR [--error-points N]
#pragma once

#include <memory>

namespace CLI {
class App;
}

namespace kairos::cli {

class TableCommand {
 public:
  virtual ~TableCommand() = default;
  virtual bool parsed() const = 0;
  // Runs the parsed subcommand; InputError for bad input. Returns the exit status.
  virtual int run() = 0;
};

// Adds the `table` subcommand (and its build, inspect and plot subcommands) to the app.
std::unique_ptr<TableCommand> add_table_command(CLI::App& app);

}  // namespace kairos::cli
