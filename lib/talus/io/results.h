// talus — reading HDF5 results files (written by every family's
// `output/results file`, formulations/common/results_file.h; layout in docs/fem.md) and comparing two of them
// (talus-compare): differences of chosen quantities as norms.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace talus::io
{
  inline constexpr const char *results_format  = "talus-results";
  inline constexpr int         results_version = 1;

  /// A table of rows x cols (row-major).
  struct Table
  {
    std::vector<double> data;
    unsigned int        cols = 0;
    std::size_t
    rows() const
    {
      return cols ? data.size() / cols : 0;
    }
  };

  /// Content of a results file (read completely on the calling rank).
  struct Results
  {
    std::string                      path;
    unsigned int                     dim = 0;
    std::string                      integration;
    double                           time = 0;
    std::vector<std::string>         series_names;
    std::vector<std::vector<double>> series; ///< by column
    Table                            grid_vertices, grid_mass, grid_displacement, grid_velocity, grid_stress;
    std::vector<std::uint64_t>       particle_id;
    Table particle_position, particle_initial_position, particle_displacement, particle_velocity, particle_stress,
      particle_volume;
  };

  /// Read a results file; InputError naming the file for a missing or
  /// unreadable file, another format or version, or missing datasets.
  Results read_results(const std::string &path);

  struct CompareOptions
  {
    /// Quantities (see quantity_help()); expanded to items by compare().
    std::vector<std::string> quantities;
    enum class Time
    {
      all,  ///< series over the common time range (b interpolated at the times of a)
      final ///< the last row of each series only
    };
    Time time = Time::all;
    enum class Norm
    {
      relative_l2,
      relative_linf,
      l2,
      linf
    };
    Norm   norm      = Norm::relative_l2;
    double tolerance = 1e-2;
  };

  /// Difference of one item (a series column, a grid or particle field or one
  /// of its components). Reference = file b. L2 is the root mean square over
  /// the n samples (nodes, points or times; all components of a field).
  struct Difference
  {
    std::string name;
    std::size_t n        = 0;
    double      l2       = 0; ///< rms(a - b)
    double      linf     = 0; ///< max |a - b|
    double      ref_l2   = 0; ///< rms(b)
    double      ref_linf = 0; ///< max |b|
    double      relative_l2() const;
    double      relative_linf() const;
    /// the value the tolerance is checked against
    double value(CompareOptions::Norm norm) const;
  };

  /// Compare a with b (reference). InputError for an unknown quantity (naming
  /// the allowed ones), a series column missing in one file, grids whose
  /// vertices do not match, particle sets with different ids, no common times.
  std::vector<Difference> compare(const Results &a, const Results &b, const CompareOptions &options);

  /// Text listing the allowed quantity names (for --help and error messages).
  std::string quantity_help();
} // namespace talus::io
