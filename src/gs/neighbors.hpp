#pragma once
// Nearest-neighbour distances for initial Gaussian scales, on a uniform grid so that the 100k+
// points of an SfM cloud or a random box take well under a second.
#include <vector>

namespace iesrgs::gs {

// Neighbours per point, as 3DGS's simple-knn takes them.
constexpr int kScaleNeighbours = 3;

// For each of the `count` points (row-major (N, 3)): the mean squared distance to its
// kScaleNeighbours nearest other points (fewer when the cloud has fewer; 0 for a lone point).
// Exact.
std::vector<float> mean_knn_squared_distance(const float* points, int count);

}  // namespace iesrgs::gs
