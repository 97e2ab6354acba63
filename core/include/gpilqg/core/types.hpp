#pragma once
/// @file types.hpp
/// Linear-algebra aliases shared by every layer. Dynamic sizes throughout: the systems have 4 to 12
/// states, and one code path for all of them is worth more than fixed-size unrolling.

#include <Eigen/Core>

namespace gpilqg {

using Vector = Eigen::VectorXd;
using Matrix = Eigen::MatrixXd;
/// Row-major storage: the order of HDF5 datasets and of C arrays handed to other libraries.
using RowMajorMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
/// Read-only view of a vector or matrix block, so callers may pass columns, rows or segments
/// without copying.
using VectorCRef = Eigen::Ref<const Vector>;
using MatrixCRef = Eigen::Ref<const Matrix>;
/// Writable view; the referenced storage must already have the right size.
using VectorRef = Eigen::Ref<Vector>;

}  // namespace gpilqg
