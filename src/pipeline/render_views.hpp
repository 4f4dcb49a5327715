#pragma once
// Rendering a trained model from a set of cameras into files: RGB PNGs named after the ground
// truth, depth as raw float32 .npy and 16-bit PNG, alpha as PNG. SR-splatting is the same with
// cameras at s times the resolution.
#include <torch/types.h>

#include <array>
#include <filesystem>
#include <vector>

#include <nlohmann/json.hpp>

#include "gs/model.hpp"
#include "io/camera.hpp"

namespace iesrgs::pipeline {

struct RenderedView {
  torch::Tensor image;  // (3, H, W) in [0, 1], over the background
  torch::Tensor depth;  // (H, W) expected camera z (blended z / alpha), 0 where nothing is drawn
  torch::Tensor alpha;  // (H, W)
};

RenderedView render_view(const gs::GaussianModel& model, const Camera& camera,
                         const std::array<float, 3>& background);

// Depth PNGs store millimetres-like units: value = depth * kDepthPngScale, clamped to 16 bits.
constexpr double kDepthPngScale = 1000.0;

// The files rendering view `name` into `dir` writes: rgb/<name>.png, depth/<name>.npy
// and .png, alpha/<name>.png.
struct RenderedViewFiles {
  std::filesystem::path rgb, depth_npy, depth_png, alpha;
};
RenderedViewFiles rendered_view_files(const std::filesystem::path& dir, const std::string& name);

// An earlier recorded render in `dir` reads as unfinished, so eval refuses it, and eval's report
// of it goes, until the next recorded render there finishes; its names stay for that render to
// clear. For a folder whose model is about to change.
void mark_render_stale(const std::filesystem::path& dir);

// Renders every camera (at `scale` times its resolution) into `dir`, printing progress; returns
// the mean rendering time in seconds per view, after one untimed warm-up frame.
double render_views_to(const std::filesystem::path& dir, const gs::GaussianModel& model,
                       const std::vector<Camera>& cameras, const std::array<float, 3>& background,
                       double scale);

// render_views_to, recorded in <dir>/render.json for eval and for a later render into the folder.
// First removes what an earlier recorded render there leaves that would mix with this one: its
// views this one does not make, and eval's report of it. render.json is written first with
// "finished": false, `record`'s own fields (the split, or the camera path), the views' count, size
// and names, the model's Gaussians and 2D filter, and the background; then again with "finished":
// true, the seconds per view and the frame rate. A render stopped partway is so known for one.
// Returns the seconds per view.
double render_views_recorded(const std::filesystem::path& dir, const gs::GaussianModel& model,
                             const std::vector<Camera>& cameras,
                             const std::array<float, 3>& background, double scale,
                             nlohmann::json record);

// The frame rate of a mean time per view; 0 when nothing was timed.
inline double frames_per_second(double seconds_per_view) {
  return seconds_per_view > 0 ? 1 / seconds_per_view : 0;
}

}  // namespace iesrgs::pipeline
