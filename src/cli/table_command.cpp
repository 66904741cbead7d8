#include "cli/table_command.hpp"

#include <fmt/format.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>

#include "core/error.hpp"
#include "core/stop_flag.hpp"
#include "interactions/soft_map_table.hpp"
#include "io/atomic_file.hpp"
#include "io/config.hpp"
#include "io/config_choices.hpp"
#include "run/environment_setup.hpp"
#include "run/setup_chain.hpp"
#include "run/soft_tables_setup.hpp"

namespace kairos::cli {
namespace {

// The flags that describe one table (a species pair's law, mu and l, and the ranges).
struct SpecFlags {
  std::string model;
  double stiffness = 0.0, damping = 0.0, reduced_mass = 0.0, contact_distance = 0.0;
  double min_speed = 0.0, max_speed = 0.0;
  double max_ratio = SoftTableSpec{}.max_tangential_ratio;
  double tolerance = SoftTableSpec{}.tolerance;
  bool head_on = false;
  std::string cache;
  int threads = 0;
  int check_points = SoftTableBuildOptions{}.check_points;
  CLI::Option* model_option = nullptr;

  void add_to(CLI::App* app) {
    model_option = app->add_option("--model", model, "Contact law: dashpot or hertz");
    app->add_option("--stiffness", stiffness,
                    "dashpot: spring constant k; hertz: prefactor rho (F = rho xi^(3/2))");
    app->add_option("--damping", damping,
                    "dashpot: gamma; hertz: the dissipative time constant A (default 0)");
    app->add_option("--reduced-mass", reduced_mass,
                    "mu = m_i m_j / (m_i + m_j) (a wall: the particle's mass)");
    app->add_option("--contact-distance", contact_distance,
                    "l = R_i + R_j (a wall: the particle's radius)");
    app->add_option("--min-speed", min_speed, "Smallest normal impact speed covered");
    app->add_option("--max-speed", max_speed, "Largest normal impact speed covered");
    app->add_option("--max-ratio", max_ratio, "Largest v_t / v_n covered (default 1000)");
    app->add_flag("--head-on", head_on, "A wall table: head-on collisions only (spans l~ only)");
    app->add_option("--tolerance", tolerance,
                    "Relative error allowed in every component (default 1e-6)");
    app->add_option("--cache", cache,
                    "Cache directory (default: " + default_soft_table_cache_dir().string() + ")");
    app->add_option("--threads", threads, "Threads for the build (default: all cores)");
    app->add_option("--check-points", check_points,
                    "Random off-grid points checked against direct integration "
                    "(default 2000)");
  }

  SoftTableSpec spec() const {
    if (model_option->count() == 0)
      throw InputError("--model (dashpot or hertz) is required to describe a table");
    const auto require = [](double x, const char* flag) {
      if (!(x > 0.0)) throw InputError(fmt::format("{} is required and must be > 0", flag));
    };
    require(stiffness, "--stiffness");
    require(reduced_mass, "--reduced-mass");
    require(contact_distance, "--contact-distance");
    require(min_speed, "--min-speed");
    require(max_speed, "--max-speed");
    SoftTableSpec s;
    s.law.model = soft_models().at(model);
    s.law.stiffness = stiffness;
    s.law.damping = damping;
    s.reduced_mass = reduced_mass;
    s.contact_distance = contact_distance;
    s.min_normal_speed = min_speed;
    s.max_normal_speed = max_speed;
    s.max_tangential_ratio = max_ratio;
    s.head_on = head_on;
    s.tolerance = tolerance;
    SoftMapTable::validate(s);
    return s;
  }

  SoftTableBuildOptions options() const {
    SoftTableBuildOptions o;
    o.threads = threads;
    o.check_points = check_points;
    // A progress line on terminals only.
    if (::isatty(STDERR_FILENO) != 0) {
      o.progress = [](double f) {
        std::fprintf(stderr, "\rbuilding the table: %5.1f %%", 100.0 * f);
        std::fflush(stderr);
      };
    }
    return o;
  }

  SoftMapTable load_or_build() const {
    const SoftTableSpec s = spec();
    const SoftTableBuildOptions o = options();
    const std::filesystem::path dir =
        cache.empty() ? default_soft_table_cache_dir() : std::filesystem::path(cache);
    SoftMapTable table = SoftMapTable::load_or_build(s, dir, o);
    if (o.progress) std::fprintf(stderr, "\r%40s\r", "");
    return table;
  }
};

std::string describe(const SoftMapTable& t) {
  const SoftTableSpec& s = t.spec();
  const SoftTableReport& r = t.report();
  const SoftTableGrid& g = t.grid();
  const bool dashpot = s.law.model == SoftModel::LinearDashpot;
  std::string out;
  const auto line = [&](const std::string& key, const std::string& value) {
    out += fmt::format("  {:<22} {}\n", key, value);
  };
  out += "Soft-sphere collision map table\n";
  if (!r.cache_file.empty()) line("file", r.cache_file.string());
  line("model", dashpot ? fmt::format("linear dashpot, k = {:.6g}, gamma = {:.6g}", s.law.stiffness,
                                      s.law.damping)
                        : fmt::format("viscoelastic Hertz, rho = {:.6g}, A = {:.6g}",
                                      s.law.stiffness, s.law.damping));
  line("pair", fmt::format("reduced mass {:.6g}, contact distance {:.6g}{}", s.reduced_mass,
                           s.contact_distance, s.head_on ? " (head-on: a wall)" : ""));
  const ReducedCollision lo = t.reduced_at(0.0, g.w_min);
  const ReducedCollision hi = t.reduced_at(0.0, g.w_min + (g.nw - 1) * g.w_step);
  line("c_dis", dashpot ? fmt::format("{:.6g}", lo.c_dis)
                        : fmt::format("{:.6g} .. {:.6g} (K l~^(-1/4))", hi.c_dis, lo.c_dis));
  line("normal speeds", fmt::format("{:.6g} .. {:.6g}", s.min_normal_speed, s.max_normal_speed));
  line("w = log10 l~", fmt::format("{:.6f} .. {:.6f} (l~ = {:.6g} .. {:.6g})", g.w_min,
                                   g.w_min + (g.nw - 1) * g.w_step, lo.l_tilde, hi.l_tilde));
  if (!s.head_on) {
    line("u = log10 v_t/v_n", fmt::format("{:.6f} .. {:.6f} (v_t/v_n up to {:.6g})", g.u_min,
                                          g.u_min + (g.nu - 1) * g.u_step, s.max_tangential_ratio));
    line("nodes", fmt::format("{} x {} = {} (u x w), spacing {:.4g} x {:.4g}", g.nu, g.nw,
                              static_cast<long>(g.nu) * g.nw, g.u_step, g.w_step));
  } else {
    line("nodes", fmt::format("{} (w), spacing {:.4g}", g.nw, g.w_step));
  }
  line("memory", fmt::format("{:.1f} KiB", static_cast<double>(g.nu) * g.nw * 3 * 8 / 1024.0));
  line("tolerance", fmt::format("{:.3g} (relative, every component)", s.tolerance));
  line("max errors",
       fmt::format("eps_t {:.3g}, eps_rdot {:.3g}, eps_phi "
                   "{:.3g}, end_overlap {:.3g} at {} "
                   "random off-grid points",
                   r.max_error[0], r.max_error[1], r.max_error[2], r.max_error[3], r.check_points));
  if (!s.head_on)
    line("v_t/v_n < 1e-4",
         r.clamps_below_min_ratio
             ? fmt::format("the u = -4 row (error {:.3g} there)", r.below_min_ratio_error)
             : fmt::format("direct integration (the u = -4 row is off by {:.3g})",
                           r.below_min_ratio_error));
  line("refinements", fmt::format("{}", r.refinements));
  line("build time", r.from_cache
                         ? fmt::format("{:.3f} s (loaded from the cache)", r.recorded_build_seconds)
                         : fmt::format("{:.3f} s", r.build_seconds));
  return out;
}

// The plot files: nodes.tsv (every node's map) and, with error points, errors.tsv (lookup against
// direct integration at a regular grid of off-grid points).
void write_plot_files(const SoftMapTable& t, const std::filesystem::path& dir, int error_points) {
  std::filesystem::create_directories(dir);
  const SoftTableGrid& g = t.grid();
  const std::string header = fmt::format(
      "# kairos table plot: the collision map over u = log10(v_t/v_n) and w = "
      "log10(l~)\n"
      "# nu {} nw {}{}\n",
      g.nu, g.nw, t.spec().head_on ? " (head-on table: u is -inf)" : "");
  std::string nodes = header;
  nodes +=
      "u\tw\tl_tilde\tc_phi\tc_dis\teps_t\teps_r\teps_rdot\teps_phi\tend_"
      "overlap\n";
  for (int j = 0; j < g.nw; ++j) {
    for (int i = 0; i < g.nu; ++i) {
      const double u = t.spec().head_on ? -INFINITY : g.u_min + i * g.u_step;
      const double w = g.w_min + j * g.w_step;
      const ReducedCollision r = t.reduced_at(u, w);
      const CollisionMap m = t.node_map(i, j);
      nodes += fmt::format(
          "{}\t{:.10g}\t{:.10g}\t{:.10g}\t{:.10g}\t{:.12g}\t{:"
          ".15g}\t{:.12g}\t{:.12g}\t{:.12g}\n",
          u, w, r.l_tilde, r.c_phi, r.c_dis, m.eps_t, m.eps_r, m.eps_rdot, m.eps_phi,
          m.end_overlap);
    }
  }
  write_text_atomically(dir / "nodes.tsv", nodes);
  write_text_atomically(dir / "report.txt", describe(t));
  if (error_points <= 0) return;
  // Cell-centred points of an error_points^2 grid (error_points along w for head-on tables).
  std::string errors = header;
  errors += "u\tw\terr_eps_t\terr_eps_rdot\terr_eps_phi\terr_end_overlap\n";
  const double u_span = (g.nu - 1) * g.u_step, w_span = (g.nw - 1) * g.w_step;
  const int n_u = t.spec().head_on ? 1 : error_points;
  for (int b = 0; b < error_points; ++b) {
    throw_if_stop_requested();  // up to 2000 x 2000 direct integrations
    for (int a = 0; a < n_u; ++a) {
      const double u = t.spec().head_on ? -INFINITY : g.u_min + (a + 0.5) / n_u * u_span;
      const double w = g.w_min + (b + 0.5) / error_points * w_span;
      CollisionUnits units;
      units.reduced = t.reduced_at(u, w);
      units.angle_unit = units.reduced.c_phi / (units.reduced.l_tilde * units.reduced.l_tilde);
      CollisionMap m;
      if (!t.lookup(units, m)) continue;
      const CollisionMap d = collision_map(units.reduced);
      const auto rel = [](double x, double y) {
        return x == y ? 0.0 : std::abs(x - y) / std::abs(y);
      };
      errors += fmt::format("{}\t{:.10g}\t{:.4g}\t{:.4g}\t{:.4g}\t{:.4g}\n", u, w,
                            rel(m.eps_t, d.eps_t), rel(m.eps_rdot, d.eps_rdot),
                            rel(m.eps_phi, d.eps_phi), rel(m.end_overlap, d.end_overlap));
    }
  }
  write_text_atomically(dir / "errors.tsv", errors);
}

// The tables `kairos run CONFIG` would use (same state, same speed range, same cache), built now or
// read from the cache; one report each. The setup chain's steps 1 to 3 (run/setup_chain.hpp), as
// `kairos run` takes them.
template <int D>
void build_config_tables(const Config& config) {
  if (!config.soft.enabled()) throw InputError("the config has no [soft] table");
  if (!config.soft.tables)
    throw InputError("soft.tables = false: the run integrates each contact and uses no table");
  if (integrators().at(config.run.integrator) != IntegratorKind::kEvent)
    throw InputError(fmt::format("run.integrator = \"{}\": only the event integrator uses tables",
                                 config.run.integrator));
  const RunStart<D> start = start_run<D>(config, std::nullopt, config.run.integrator);
  Environment<D> env = make_environment<D>(start.config, start.state);
  // A progress line on terminals only (as for a table from flags): a log gets no \r lines.
  const bool tell = ::isatty(STDERR_FILENO) != 0;
  const std::vector<SoftTableUse> used =
      start_tables(env, start, [tell](const std::string& contact, double f) {
        if (!tell) return;
        std::fprintf(stderr, "\rbuilding the table of %s: %5.1f %%", contact.c_str(), 100.0 * f);
        std::fflush(stderr);
      });
  if (tell) std::fprintf(stderr, "\r%60s\r", "");
  for (const SoftTableUse& use : used) {
    fmt::print("contact {}\n", use.contact);
    fmt::print("{}", describe(SoftMapTable::read_file(use.report.cache_file)));
  }
}

class TableCommandImpl final : public TableCommand {
 public:
  explicit TableCommandImpl(CLI::App& app) {
    table_ = app.add_subcommand("table",
                                "Build, inspect and plot lookup tables of "
                                "the soft-sphere collision map.");
    table_->require_subcommand(1);
    table_->footer("Tables are cached in a directory (--cache, default " +
                   default_soft_table_cache_dir().string() +
                   ") under a name made from the spec; delete the directory to "
                   "clear the cache. "
                   "See docs/soft_tables.md.");
    build_ = table_->add_subcommand("build",
                                    "Build (or load from the cache) the table "
                                    "of one contact and print its report.");
    build_flags_.add_to(build_);
    build_->add_option("--config", config_file_,
                       "Instead of the flags: the tables `kairos run CONFIG` would use (every "
                       "species pair and wall of its [soft] laws, its state's speed range and "
                       "soft.table_cache)");
    build_->add_option("--set", overrides_, "key=value override of the config (repeatable)");
    build_->footer(
        "Example: kairos table build --model hertz --stiffness 1e5 "
        "--damping 1e-4 "
        "--reduced-mass 0.5 --contact-distance 1 --min-speed 0.01 "
        "--max-speed 10");

    inspect_ = table_->add_subcommand("inspect", "Print the report stored in a table file.");
    inspect_->add_option("file", inspect_file_, "Table file (soft_map_*.bin)")->required();

    plot_ = table_->add_subcommand("plot",
                                   "Write a table's nodes (and optionally its errors) as TSV for "
                                   "examples/plot/plot_soft_table.py.");
    plot_->add_option("file", plot_file_, "Table file (or give the build flags instead)");
    plot_flags_.add_to(plot_);
    plot_->add_option("-o,--output", plot_dir_, "Directory for nodes.tsv, errors.tsv, report.txt")
        ->required();
    plot_->add_option("--error-points", error_points_,
                      "Also write errors.tsv: lookup against direct integration on an N x N "
                      "grid of off-grid points (default 0: none)");
  }

  bool parsed() const override { return table_->parsed(); }

  int run() override {
    if (build_->parsed() && !config_file_.empty()) {
      if (build_flags_.model_option->count() > 0)
        throw InputError("kairos table build: give either --config or the table flags");
      const Config config = load_config(config_file_, overrides_);
      if (config.system.dimension == 2) {
        build_config_tables<2>(config);
      } else {
        build_config_tables<3>(config);
      }
      return 0;
    }
    if (build_->parsed()) {
      const SoftMapTable t = build_flags_.load_or_build();
      fmt::print("{}", describe(t));
      return 0;
    }
    if (inspect_->parsed()) {
      fmt::print("{}", describe(SoftMapTable::read_file(inspect_file_)));
      return 0;
    }
    if (plot_dir_.empty()) throw InputError("-o/--output: the directory must not be empty");
    const bool has_flags = plot_flags_.model_option->count() > 0;
    if (plot_file_.empty() == !has_flags)
      throw InputError("kairos table plot: give either a table file or the build flags");
    if (error_points_ < 0 || error_points_ > 2000)
      throw InputError("--error-points must be in [0, 2000]");
    const SoftMapTable t =
        plot_file_.empty() ? plot_flags_.load_or_build() : SoftMapTable::read_file(plot_file_);
    write_plot_files(t, plot_dir_, error_points_);
    fmt::print("{}wrote {}/nodes.tsv{}, report.txt\n", describe(t), plot_dir_,
               error_points_ > 0 ? ", errors.tsv" : "");
    return 0;
  }

 private:
  CLI::App* table_ = nullptr;
  CLI::App* build_ = nullptr;
  CLI::App* inspect_ = nullptr;
  CLI::App* plot_ = nullptr;
  SpecFlags build_flags_, plot_flags_;
  std::string inspect_file_, plot_file_, plot_dir_, config_file_;
  std::vector<std::string> overrides_;
  int error_points_ = 0;
};

}  // namespace

std::unique_ptr<TableCommand> add_table_command(CLI::App& app) {
  return std::make_unique<TableCommandImpl>(app);
}

}  // namespace kairos::cli
