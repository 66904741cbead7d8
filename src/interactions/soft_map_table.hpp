// Lookup tables of the Müller–Pöschel collision map (formulas.md §1.5) for one soft contact:
// one species pair (or a species against a wall) under one SoftContactLaw.
//
// For a fixed law, reduced mass mu and contact distance l, the reduced parameters of a
// collision (c_phi, l~, c_dis) depend only on the impact velocity (v_n, v_t): the dashpot's
// c_dis is a constant, the Hertz c_dis = K l~^(-1/4) with the dimensionless
// K = A (rho/mu)^(1/2) l^(1/4). A table therefore spans the plane
//   u = log10(v_t / v_n) = log10(c_phi / l~),   w = log10(l~),
// at the pair's constant (c_dis or K), over the range of normal impact speeds a run needs.
// A head-on table (walls: v_t plays no part, the flat wall's force is normal) spans w only.
//
// Interpolation is local and of fourth order (tensor-product cubic Lagrange on a uniform grid);
// the grid is refined until random off-grid points agree with direct integration
// (collision_map) to the requested tolerance, checked when the table is built. Outside the
// table, lookup() returns false and the caller integrates directly.
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
  // Largest v_t / v_n covered (grazing collisions beyond it integrate directly), > 0; the
  // smallest is 10^-4 (below it the head-on limit holds to far better than any tolerance).
  double max_tangential_ratio = 1e3;
  bool head_on = false;     // a wall table: c_phi = 0 only
  double tolerance = 1e-6;  // relative, every stored component (see SoftMapTable::check)
};

struct SoftTableBuildOptions {
  int threads = 0;  // 0: std::thread::hardware_concurrency()
  // Off-grid points compared with direct integration after the build.
  int check_points = 2000;
  std::uint64_t seed = 1;  // of the check points
  // Called now and then with the fraction done (0..1), e.g. for a progress bar.
  std::function<void(double)> progress;
};

// What the build measured (also stored in the cache file).
struct SoftTableReport {
  std::vector<int> nodes;         // per axis (u, w), or (w) for a head-on table
  double build_seconds = 0.0;     // integration of the nodes and the check (0 when loaded)
  double max_error[4] = {};       // per component at the check points, relative (see check)
  int check_points = 0;
  int refinements = 0;            // grid halvings needed to reach the tolerance
  bool from_cache = false;
  std::filesystem::path cache_file;  // empty when not cached
};

class SoftMapTable {
 public:
  // Builds the table (integrating every node with collision_map), refining the grid until the
  // off-grid check meets spec.tolerance. InputError for an invalid spec; std::runtime_error if
  // the tolerance cannot be met within the node limit.
  static SoftMapTable build(const SoftTableSpec& spec, const SoftTableBuildOptions& options = {});
  // The same, through a cache directory: a file keyed by the spec (and the file format version)
  // is read if present and valid, otherwise built and written atomically. An unreadable or
  // stale file is rebuilt, never trusted.
  static SoftMapTable load_or_build(const SoftTableSpec& spec,
                                    const std::filesystem::path& cache_dir,
                                    const SoftTableBuildOptions& options = {});

  // The map of a collision of this table's law, mu and l (units from reduce_collision): fills
  // eps_t, eps_r, eps_rdot, eps_phi, end_overlap, eps_phidot (= eps_r^-2) and phi_c
  // (= eps_phi * units.angle_unit) and returns true, or returns false (map untouched) when
  // (u, w) lies outside the table.
  bool lookup(const CollisionUnits& units, CollisionMap& map) const;

  const SoftTableSpec& spec() const { return spec_; }
  const SoftTableReport& report() const { return report_; }

 private:
  SoftTableSpec spec_;
  SoftTableReport report_;
  // Implementation's grid and data (the helper defines them).
  double u_min_ = 0.0, u_step_ = 0.0, w_min_ = 0.0, w_step_ = 0.0;
  int nu_ = 0, nw_ = 0;
  std::vector<double> data_;  // 4 components per node
};

}  // namespace kairos
