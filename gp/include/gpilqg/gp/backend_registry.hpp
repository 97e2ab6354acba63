#pragma once
/// @file backend_registry.hpp
/// GP backends by name, for the command line (`--backends exact,fitc,ssgp`), configs and loading saved
/// models. One table maps each registry name to a factory, so a new backend is one entry here and is
/// then available to `gpilqg run`, `gpilqg profile` and `gpilqg diagnose` alike.

#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "gpilqg/gp/backend.hpp"

namespace gpilqg::gp {

/// The size settings every backend is built from (each backend reads the ones that concern it).
struct BackendSettings {
  int exact_points = 300;   ///< "exact": size of the uniform subsample (the paper's 300)
  int inducing = 100;       ///< "fitc": M pseudo-inputs
  int frequencies = 100;    ///< "ssgp": m spectral points
  int compact_neighbours = 32;  ///< "compact": neighbours per point at the data-driven start
  int compact_max_neighbours = 256;  ///< "compact": CompactOptions::max_neighbours (>= compact_neighbours)
  int threads = 1;          ///< threads inside one NLML evaluation
  /// Throws std::invalid_argument naming the field when a size is < 1.
  void validate() const;
};

/// The registry names, in a fixed order: "exact", "fitc", "ssgp", "compact".
std::vector<std::string> backend_names();

/// The registry names of the backends that take a noise variance known per point
/// (GpBackend::takes_known_noise), in the order of backend_names().
std::vector<std::string> backends_taking_known_noise();

/// The backend called `name`. Throws std::invalid_argument naming `name` and listing the known names.
std::unique_ptr<GpBackend> make_backend(std::string_view name, const BackendSettings& settings = {});

/// Splits a comma-separated list ("exact,fitc"), trimming spaces, and checks every name. Throws
/// std::invalid_argument for an empty list, an empty or unknown entry (listing the known names), or
/// a name given twice.
std::vector<std::string> parse_backend_list(std::string_view list);

}  // namespace gpilqg::gp
