#include "gs/neighbors.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

namespace iesrgs::gs {

namespace {

// Points bucketed by cell: cell c holds order[start[c] .. start[c + 1]).
// In double: the spread of float coordinates near the float limit overflows a float.
struct PointGrid {
  std::array<double, 3> origin{};
  double cell = 1;
  std::array<int, 3> dims{1, 1, 1};
  std::vector<int> start, order;

  std::array<int, 3> cell_of(const float* p) const {
    std::array<int, 3> c;
    // Clamped before the conversion: an outlier's cell number need not fit an int.
    for (int a = 0; a < 3; ++a)
      c[a] = int(std::clamp((p[a] - origin[a]) / cell, 0.0, double(dims[a] - 1)));
    return c;
  }
  int index(int x, int y, int z) const { return (z * dims[1] + y) * dims[0] + x; }
};

// The grid covers the central 98 % of the points along each axis; the others fall into its
// border cells. Sized to the whole box, one far outlier (SfM clouds have them) would crowd every
// other point into a few cells and make the search quadratic. About one point per cell for a
// cloud filling its box; flatter clouds get more per cell.
PointGrid build_grid(const float* points, int count) {
  PointGrid grid;
  std::array<double, 3> hi;
  std::vector<float> axis(count);
  const int low_rank = count / 100, high_rank = count - 1 - count / 100;
  for (int a = 0; a < 3; ++a) {
    for (int i = 0; i < count; ++i) axis[i] = points[3 * i + a];
    std::nth_element(axis.begin(), axis.begin() + low_rank, axis.end());
    grid.origin[a] = axis[low_rank];
    std::nth_element(axis.begin() + low_rank, axis.begin() + high_rank, axis.end());
    hi[a] = axis[high_rank];
  }
  const double span = std::max({hi[0] - grid.origin[0], hi[1] - grid.origin[1],
                                hi[2] - grid.origin[2], double(std::numeric_limits<float>::min())});
  grid.cell = span / std::max(1.0, std::cbrt(double(count)));
  for (int a = 0; a < 3; ++a) grid.dims[a] = int((hi[a] - grid.origin[a]) / grid.cell) + 1;

  const int cells = grid.dims[0] * grid.dims[1] * grid.dims[2];
  std::vector<int> cell_of_point(count);
  grid.start.assign(cells + 1, 0);
  for (int i = 0; i < count; ++i) {
    const auto c = grid.cell_of(points + 3 * i);
    cell_of_point[i] = grid.index(c[0], c[1], c[2]);
    ++grid.start[cell_of_point[i] + 1];
  }
  for (int c = 0; c < cells; ++c) grid.start[c + 1] += grid.start[c];
  grid.order.resize(count);
  std::vector<int> fill(grid.start.begin(), grid.start.end() - 1);
  for (int i = 0; i < count; ++i) grid.order[fill[cell_of_point[i]]++] = i;
  return grid;
}

// The k smallest squared distances seen so far, ascending.
struct NearestK {
  int k;
  std::array<float, kScaleNeighbours> d2;
  int found = 0;

  void offer(float d) {
    if (found == k && d >= d2[k - 1]) return;
    int i = found < k ? found++ : k - 1;
    for (; i > 0 && d2[i - 1] > d; --i) d2[i] = d2[i - 1];
    d2[i] = d;
  }
  bool full() const { return found == k; }
};

// Visits the cells at Chebyshev distance exactly `ring` from `home`.
void scan_ring(const PointGrid& grid, const float* points, int self, const std::array<int, 3>& home,
               int ring, NearestK& best) {
  const float* p = points + 3 * self;
  for (int dz = -ring; dz <= ring; ++dz)
    for (int dy = -ring; dy <= ring; ++dy)
      for (int dx = -ring; dx <= ring; ++dx) {
        if (std::max({std::abs(dx), std::abs(dy), std::abs(dz)}) != ring) continue;
        const int x = home[0] + dx, y = home[1] + dy, z = home[2] + dz;
        if (x < 0 || y < 0 || z < 0 || x >= grid.dims[0] || y >= grid.dims[1] || z >= grid.dims[2])
          continue;
        const int c = grid.index(x, y, z);
        for (int j = grid.start[c]; j < grid.start[c + 1]; ++j) {
          const int other = grid.order[j];
          if (other == self) continue;
          const float* q = points + 3 * other;
          const float ex = p[0] - q[0], ey = p[1] - q[1], ez = p[2] - q[2];
          best.offer(ex * ex + ey * ey + ez * ez);
        }
      }
}

}  // namespace

std::vector<float> mean_knn_squared_distance(const float* points, int count) {
  std::vector<float> result(count, 0.f);
  if (count < 2) return result;
  const PointGrid grid = build_grid(points, count);
  const int max_ring = std::max({grid.dims[0], grid.dims[1], grid.dims[2]});
  const int wanted = std::min(kScaleNeighbours, count - 1);
#pragma omp parallel for schedule(dynamic, 256)
  for (int i = 0; i < count; ++i) {
    const auto home = grid.cell_of(points + 3 * i);
    NearestK best{wanted, {}};
    // Any point beyond ring r lies at least r cells away, so the search may stop once the
    // k-th best is within that bound.
    for (int ring = 0; ring <= max_ring; ++ring) {
      scan_ring(grid, points, i, home, ring, best);
      const double reach = ring * grid.cell;
      if (best.full() && best.d2[wanted - 1] <= reach * reach) break;
    }
    float sum = 0;
    for (int j = 0; j < wanted; ++j) sum += best.d2[j];
    result[i] = sum / wanted;
  }
  return result;
}

}  // namespace iesrgs::gs
