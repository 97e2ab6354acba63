#pragma once
/// @file peer_input.hpp
/// The input of gpilqg_peer_cases: the data sets and hyperparameters compare_peers.py writes to one
/// HDF5 file, so that gpilqg and its peers see the same numbers bit for bit. Layout (every array
/// float64, matrices N x D with one point per row):
///
///   /exact/X       N x D training inputs of the exact-GP cases
///   /exact/y       N     training targets
///   /exact/theta   D + 2 hyperparameters [log l_1..log l_D, log sf, log sn] (hyperparameters.hpp)
///   /exact/X_test  P x D test inputs of the prediction case
///   /fitc/X, /fitc/y   training set of the FITC case (its own N, the same D)
///   /fitc/theta    D + 2 + M D: the hyperparameters, then the M x D pseudo-inputs column-major
///                  (fitc.hpp, FitcLayout)
///   root attributes: nlml_sizes (list of N, the first N rows of /exact), fit_size, fit_sizes (list),
///                    predict_size
///
/// Every size must be between D and the rows of /exact; values must be finite.

#include <filesystem>
#include <vector>

#include "gpilqg/core/types.hpp"
#include "gpilqg/gp/training_set.hpp"

namespace gpilqg::bench {

struct PeerInput {
  gp::TrainingSet exact;
  Vector exact_theta;
  Matrix test_points;
  gp::TrainingSet fitc;
  Vector fitc_theta;
  int fitc_inducing = 0;        ///< M, read from the length of /fitc/theta
  std::vector<int> nlml_sizes;  ///< case a: NLML and gradient on the first N rows
  int fit_size = 0;             ///< case b: a whole fit on the first N rows
  std::vector<int> fit_sizes;   ///< case e: whole fits from the default start on the first N rows
  int predict_size = 0;         ///< case d: conditioned on the first N rows, predicting /exact/X_test
};

/// Reads and checks the file. Throws std::runtime_error naming the file and the dataset or attribute
/// that is missing, mis-shaped, out of range or not finite.
PeerInput read_peer_input(const std::filesystem::path& file);

}  // namespace gpilqg::bench
