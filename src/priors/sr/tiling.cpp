#include "priors/sr/tiling.hpp"

#include <algorithm>
#include <vector>

#include "core/error.hpp"
#include "io/image_tensor.hpp"

namespace iesrgs::priors::sr {

namespace {

struct Span {
  int64_t begin, end;  // input pixels
};

// Tiles of `tile` pixels every tile - overlap pixels, the last one flush with the end.
std::vector<Span> tile_spans(int64_t length, int64_t tile, int64_t overlap) {
  if (length <= tile) return {{0, length}};
  std::vector<Span> spans;
  for (int64_t begin = 0; begin + tile < length; begin += tile - overlap)
    spans.push_back({begin, begin + tile});
  spans.push_back({length - tile, length});
  return spans;
}

// 0 before the middle half of [begin, end), 1 after it, linear in between; a step at `begin`
// for an empty overlap.
float rise(double x, int64_t begin, int64_t end) {
  const double width = double(end - begin);
  if (width <= 0) return x >= double(begin) ? 1.f : 0.f;
  return float(std::clamp((x - begin - width / 4) / (width / 2), 0.0, 1.0));
}

// Per tile, its weight at each output pixel it covers along one axis; the weights of all tiles
// sum to 1 at every output pixel.
std::vector<torch::Tensor> blend_weights(const std::vector<Span>& spans, int64_t scale) {
  const int64_t length = spans.back().end * scale;
  std::vector<std::vector<float>> raw(spans.size());
  std::vector<double> total(size_t(length), 0.0);
  for (size_t k = 0; k < spans.size(); ++k) {
    for (int64_t u = spans[k].begin * scale; u < spans[k].end * scale; ++u) {
      const double x = (u + 0.5) / double(scale);  // pixel centre in input pixels
      float w = 1.f;
      if (k > 0) w = std::min(w, rise(x, spans[k].begin, spans[k - 1].end));
      if (k + 1 < spans.size()) w = std::min(w, 1.f - rise(x, spans[k + 1].begin, spans[k].end));
      raw[k].push_back(w);
      total[size_t(u)] += w;
    }
  }
  std::vector<torch::Tensor> weights;
  for (size_t k = 0; k < spans.size(); ++k) {
    const int64_t first = spans[k].begin * scale;
    for (size_t i = 0; i < raw[k].size(); ++i) raw[k][i] = float(raw[k][i] / total[first + i]);
    weights.push_back(torch::tensor(raw[k]));
  }
  return weights;
}

}  // namespace

torch::Tensor upscale_tiled(SrNet& net, const torch::Tensor& rgb, const TileOptions& options) {
  check_rgb_batch(rgb, net.name());
  if (options.overlap < 0 || (options.tile > 0 && options.overlap >= options.tile))
    fail(
        "tiled super-resolution: the overlap ({}, --tile-overlap) must be at least 0 and smaller "
        "than the tile ({}, --tile)",
        options.overlap, options.tile);
  const int64_t height = rgb.size(2), width = rgb.size(3), scale = net.scale();
  if (options.tile <= 0 || (height <= options.tile && width <= options.tile))
    return net.upscale(rgb);

  const std::vector<Span> rows = tile_spans(height, options.tile, options.overlap);
  const std::vector<Span> cols = tile_spans(width, options.tile, options.overlap);
  const std::vector<torch::Tensor> row_weights = blend_weights(rows, scale);
  const std::vector<torch::Tensor> col_weights = blend_weights(cols, scale);
  torch::Tensor out = torch::zeros({1, 3, height * scale, width * scale});
  for (size_t r = 0; r < rows.size(); ++r) {
    const int64_t h = rows[r].end - rows[r].begin;
    for (size_t c = 0; c < cols.size(); ++c) {
      const int64_t w = cols[c].end - cols[c].begin;
      const torch::Tensor tile =
          rgb.narrow(2, rows[r].begin, h).narrow(3, cols[c].begin, w).contiguous();
      const torch::Tensor weight =
          row_weights[r].view({1, 1, -1, 1}) * col_weights[c].view({1, 1, 1, -1});
      out.narrow(2, rows[r].begin * scale, h * scale)
          .narrow(3, cols[c].begin * scale, w * scale)
          .addcmul_(net.upscale(tile), weight);
    }
  }
  return out;
}

}  // namespace iesrgs::priors::sr
