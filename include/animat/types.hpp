#pragma once
// Array types shared by every stage. Row-major so they map onto numpy (n, 2) arrays without copies.
#include <Eigen/Core>
#include <array>
#include <vector>

namespace animat {

using Points = Eigen::Matrix<double, Eigen::Dynamic, 2, Eigen::RowMajor>;  ///< n × 2 positions
/// m × 2 node indices
using IndexPairs = Eigen::Matrix<int, Eigen::Dynamic, 2, Eigen::RowMajor>;
using Vector = Eigen::VectorXd;

}  // namespace animat
