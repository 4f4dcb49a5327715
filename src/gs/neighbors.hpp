#pragma once
// Nearest-neighbour distances for initial Gaussian scales, on a uniform grid so that the 100k+
// points of an SfM cloud or a random box take well under a second.
#include <vector>

namespace iesrgs::gs {

// For each of the `count` points (row-major (N, 3)): the mean squared distance to its `k`
// nearest other points (fewer when the cloud has fewer; 0 for a lone point). Exact.
std::vector<float> mean_knn_squared_distance(const float* points, int count, int k = 3);

}  // namespace iesrgs::gs
