// Lookup tables of the Müller–Pöschel collision map (docs/physics.md#map-tables) for one soft
// contact: one species pair (or a species against a wall) under one SoftContactLaw.
//
// For a fixed law, reduced mass mu and contact distance l, the reduced parameters of a collision
// (c_phi, l~, c_dis) depend only on the impact velocity (v_n, v_t): the dashpot's c_dis is a
// constant, the Hertz c_dis = K l~^(-1/4) with the dimensionless K = A (rho/mu)^(1/2) l^(1/4). A
// table therefore spans the plane
//   u = log10(v_t / v_n) = log10(c_phi / l~),   w = log10(l~),
// at the pair's constant (c_dis or K), over the range of normal impact speeds a run needs. A
// head-on table (walls: v_t plays no part, the flat wall's force is normal) spans w only.
//
// Interpolation is local and of fourth order (tensor-product cubic Lagrange on a uniform grid); the
// grid is refined until random off-grid points agree with direct integration (collision_map) to the
// requested tolerance, checked when the table is built. Outside the table, lookup() returns false
// and the caller integrates directly.
//
// What is stored: per node ln(eps_t), ln(-eps_rdot) and ln(eps_phi). All three are positive
// quantities that become power laws of v_t/v_n and l~ for grazing collisions (eps_t and eps_phi ~
// l~ (v_n/v_t)^2 down to 1e-6 and below), where the logarithms are nearly linear and an
// interpolation error is directly a relative error. end_overlap is not stored: the contact ends
// where the force is zero, so end_overlap = kappa~ (-eps_rdot) exactly, with kappa~ = c_dis
// (dashpot) or (3/2) c_dis (Hertz) (collision_map agrees to round-off).
//
// Relative error (SoftMapTable::check, the tolerance and SoftTableReport::max_error), per component
// of {eps_t, eps_rdot, eps_phi, end_overlap}: |table - direct| / |direct|. None of them changes
// sign over a table (eps_t, eps_phi > 0; eps_rdot < 0; end_overlap > 0, or identically 0 for an
// elastic law, which the table reproduces exactly: 0/0 counts as 0), and each enters the rebuilt
// state as a factor (phi_c = eps_phi Phi, r(t_c) = l - end_overlap L, ...), so the plain relative
// error is the one that matters even where a component is tiny.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "interactions/soft_contact.hpp"

namespace kairos {

struct SoftTableSpec {
  SoftContactLaw law;
  double reduced_mass = 0.5;      // mu > 0 (a wall: the particle's mass)
  double contact_distance = 1.0;  // l = R_i + R_j > 0 (a wall: the particle's radius)
  // Normal impact speeds covered, 0 < min < max.
  double min_normal_speed = 1e-3;
  double max_normal_speed = 10.0;
  // Largest v_t / v_n covered (grazing collisions beyond it integrate directly), > 0; the smallest
  // is 10^-4 (below it the head-on limit holds to far better than any tolerance).
  double max_tangential_ratio = 1e3;
  bool head_on = false;     // a wall table: c_phi = 0 only
  double tolerance = 1e-6;  // relative, every stored component (see SoftMapTable::check)
};

struct SoftTableBuildOptions {
  int threads = 0;  // 0: std::thread::hardware_concurrency()
  // Off-grid points compared with direct integration after the build.
  int check_points = 2000;
  std::uint64_t seed = 1;  // of the check points
  // Called now and then with the fraction done (0..1), e.g. for a progress bar. Called from the
  // building thread only; the fraction is that of the current refinement level.
  std::function<void(double)> progress;
};

// What the build measured (also stored in the cache file).
struct SoftTableReport {
  std::vector<int> nodes;      // per axis (u, w), or (w) for a head-on table
  double build_seconds = 0.0;  // integration of the nodes and the check (0 when loaded)
  double max_error[4] = {};    // per component at the check points, relative (see check)
  int check_points = 0;
  int refinements = 0;  // grid halvings needed to reach the tolerance
  bool from_cache = false;
  std::filesystem::path cache_file;     // empty when not cached
  double recorded_build_seconds = 0.0;  // build_seconds of the build that made this table
  // Collisions with v_t/v_n below 10^-4 (head-on included) take the u = -4 row: allowed only when
  // points there (u in [-8, -4) and v_t = 0) met the tolerance at the build, with this largest
  // error over the four components. A head-on table has no such limit (true, 0).
  bool clamps_below_min_ratio = false;
  double below_min_ratio_error = 0.0;
};

// Names of the four components of SoftTableReport::max_error, in order.
inline constexpr const char* kSoftTableComponents[4] = {"eps_t", "eps_rdot", "eps_phi",
                                                        "end_overlap"};

// The grid of a table: u (log10 v_t/v_n) and w (log10 l~) at node (i, j) are u_min + i u_step and
// w_min + j w_step; a head-on table has nu = 1 (u unused).
struct SoftTableGrid {
  double u_min = 0.0, u_step = 0.0;
  int nu = 1;
  double w_min = 0.0, w_step = 0.0;
  int nw = 0;
};

class SoftMapTable {
 public:
  // Builds the table (integrating every node with collision_map), refining the grid until the
  // off-grid check meets spec.tolerance. InputError for an invalid spec; InputError too if the
  // tolerance cannot be met within the node limit.
  static SoftMapTable build(const SoftTableSpec& spec, const SoftTableBuildOptions& options = {});
  // The same, through a cache directory: a file keyed by the spec (and the file format version) is
  // read if present and valid, otherwise built and written atomically. An unreadable or stale file
  // is rebuilt, never trusted.
  static SoftMapTable load_or_build(const SoftTableSpec& spec,
                                    const std::filesystem::path& cache_dir,
                                    const SoftTableBuildOptions& options = {});

  // The map of a collision of this table's law, mu and l (units from reduce_collision): fills
  // eps_t, eps_r, eps_rdot, eps_phi, end_overlap, eps_phidot (= eps_r^-2) and phi_c (= eps_phi *
  // units.angle_unit) and returns true, or returns false (map untouched) when (u, w) lies outside
  // the table. steps is set to 0. A head-on table ignores c_phi (walls: the caller passes v_t = 0,
  // so phi_c = 0). std::logic_error if the units are not of this table's model and c_dis (units of
  // another pair).
  bool lookup(const CollisionUnits& units, CollisionMap& map) const;

  const SoftTableSpec& spec() const { return spec_; }
  const SoftTableReport& report() const { return report_; }

  // --- Additions (CLI, plots, tests) ---

  const SoftTableGrid& grid() const { return grid_; }
  // The reduced parameters of the table's collision at (u, w) (c_phi = 0 for a head-on table).
  ReducedCollision reduced_at(double u, double w) const;
  // The stored map at node (i, j) (i = 0 for a head-on table), every field filled as by lookup.
  CollisionMap node_map(int i, int j) const;

  // The cache file of a spec and build options (those that determine the content: the check's
  // points and seed): "soft_map_<hash>.bin" in the cache directory.
  static std::filesystem::path cache_file_name(const SoftTableSpec& spec,
                                               const SoftTableBuildOptions& options = {});
  // Reads a table file written by load_or_build or write_file; InputError naming the file and what
  // is wrong (not a table, other format version, truncated, checksum, bad values). The report says
  // from_cache, with cache_file = file.
  static SoftMapTable read_file(const std::filesystem::path& file);
  // Writes the table (atomically: a temporary file beside it, then a rename).
  void write_file(const std::filesystem::path& file) const;

  // InputError naming the offending field of an invalid spec.
  static void validate(const SoftTableSpec& spec);

 private:
  SoftTableSpec spec_;
  SoftTableReport report_;
  SoftTableGrid grid_;
  double inv_u_step_ = 0.0, inv_w_step_ = 0.0;
  double min_ratio_ = 0.0;        // 10^u_min: v_t/v_n below it is below the table
  double kappa_ = 0.0;            // end_overlap = kappa_ c_dis (-eps_rdot): 1 or 3/2
  double c_dis_ = 0.0;            // dashpot: c_dis; Hertz: K (c_dis = K l~^(-1/4))
  double c_dis4_ = 0.0;           // Hertz: K^4 (the consistency check c_dis^4 l~ = K^4)
  std::uint64_t check_seed_ = 1;  // SoftTableBuildOptions::seed of the build (part of the key)
  std::vector<double> data_;      // 3 per node (ln eps_t, ln -eps_rdot, ln eps_phi), u fastest

  friend struct SoftMapTableBuilder;
  void set_grid(const SoftTableGrid& grid);
  void interpolate(double su, double sw, double out[3]) const;
  void fill(const double logs[3], const CollisionUnits& units, CollisionMap& map) const;
};

// Where tables are cached by default: $KAIROS_CACHE_DIR/soft_tables, else
// $XDG_CACHE_HOME/kairos/soft_tables, else $HOME/.cache/kairos/soft_tables, else
// ./.kairos-cache/soft_tables.
std::filesystem::path default_soft_table_cache_dir();

}  // namespace kairos
