#include "pipeline/render_views.hpp"

#include <fmt/core.h>
#include <spdlog/spdlog.h>
#include <torch/torch.h>

#include <algorithm>
#include <cmath>

#include "core/error.hpp"
#include "core/interrupt.hpp"
#include "core/memory.hpp"
#include "core/stopwatch.hpp"
#include "io/atomic_file.hpp"
#include "io/image.hpp"
#include "io/image_tensor.hpp"
#include "io/npy.hpp"
#include "raster/autograd.hpp"
#include "raster/rasterizer.hpp"

namespace iesrgs::pipeline {

namespace {

constexpr float kMinAlphaForDepth = 1e-4f;
// The rasterizer's planes, the render's tensors and the files' encodings of one view: 56 bytes a
// pixel, measured on the CPU as the growth of the peak resident memory from 2048x2048 to
// 4096x4096 renders, and a margin for the Gaussians' own buffers, which that growth leaves out.
constexpr int64_t kRenderBytesPerPixel = 64;

std::vector<float> to_vector(const torch::Tensor& tensor) {
  const torch::Tensor flat = tensor.contiguous().view(-1);
  return std::vector<float>(flat.data_ptr<float>(), flat.data_ptr<float>() + flat.numel());
}

Image8 gray_image8(const torch::Tensor& plane) {
  const torch::Tensor bytes = (plane.clamp(0, 1) * 255.0f).round().to(torch::kUInt8).contiguous();
  Image8 image(int(plane.size(1)), int(plane.size(0)), 1);
  std::copy_n(bytes.data_ptr<uint8_t>(), image.data.size(), image.data.begin());
  return image;
}

// Whether `name` stays inside the folder it is joined to (a COLMAP view's name may hold folders).
bool inside_folder(const std::string& name) {
  const std::filesystem::path path(name);
  if (name.empty() || path.has_root_path()) return false;
  return std::none_of(path.begin(), path.end(), [](const auto& part) { return part == ".."; });
}

void remove_earlier_file(const std::filesystem::path& file) {
  remove_earlier_output(file, "left by an earlier render");
}

// Eval's report of an earlier render in `dir`, from its default location.
void remove_eval_report(const std::filesystem::path& dir) {
  for (const char* scores : {"metrics.json", "metrics.csv"}) remove_earlier_file(dir / scores);
}

// What an earlier render into the folder leaves that would mix with this one, of the views
// `names`: the views listed in its render.json that this one does not make (fewer path frames,
// another split), and the report of eval's default location, which scored its views. Only those
// files, and none outside the folder whatever render.json says.
void remove_earlier_render(const std::filesystem::path& dir,
                           const std::vector<std::string>& names) {
  const std::filesystem::path report = dir / "render.json";
  if (!std::filesystem::exists(report)) return;
  remove_eval_report(dir);
  const nlohmann::json earlier = nlohmann::json::parse(read_file(report), nullptr, false);
  if (!earlier.is_object() || !earlier.contains("names") || !earlier["names"].is_array()) return;
  for (const nlohmann::json& name : earlier["names"]) {
    if (!name.is_string()) continue;
    const std::string view = name.get<std::string>();
    if (!inside_folder(view) || std::find(names.begin(), names.end(), view) != names.end())
      continue;
    const RenderedViewFiles files = rendered_view_files(dir, view);
    for (const std::filesystem::path& file :
         {files.rgb, files.depth_npy, files.depth_png, files.alpha})
      remove_earlier_file(file);
  }
}

}  // namespace

void mark_render_stale(const std::filesystem::path& dir) {
  const std::filesystem::path report = dir / "render.json";
  if (!std::filesystem::exists(report)) return;
  remove_eval_report(dir);
  nlohmann::json record = nlohmann::json::parse(read_file(report), nullptr, false);
  if (!record.is_object()) record = nlohmann::json::object();  // damaged: no names to keep
  record["finished"] = false;
  write_file_atomically(report, record.dump(2) + "\n");
}

namespace {

// Refuses views too large for the memory before rendering any: the kernel would kill the process
// partway through. The CPU's alone, which holds every view's outputs and encodes the files: on a
// GPU the free memory leaves out what LibTorch has cached, and running out there is an error
// LibTorch reports.
void require_render_memory(const std::vector<Camera>& cameras, double scale) {
  Intrinsics largest;
  for (const Camera& camera : cameras) {
    const Intrinsics size = camera.scaled(scale).intrinsics;
    if (int64_t(size.width) * size.height > int64_t(largest.width) * largest.height) largest = size;
  }
  require_memory(int64_t(largest.width) * largest.height * kRenderBytesPerPixel,
                 fmt::format("rendering {}x{} views", largest.width, largest.height));
}

}  // namespace

RenderedView render_view(const gs::GaussianModel& model, const Camera& camera,
                         const std::array<float, 3>& background) {
  torch::NoGradGuard no_grad;
  const raster::RenderOutput out = raster::render(raster::render_tensors(model),
                                                  raster::raster_camera<float>(camera), background);
  const torch::Tensor drawn = out.alpha > kMinAlphaForDepth;
  RenderedView view;  // on the CPU, wherever the model renders
  view.image = out.image.clamp(0, 1).cpu();
  view.depth = torch::where(drawn, out.depth / out.alpha.clamp_min(kMinAlphaForDepth),
                            torch::zeros_like(out.depth))
                   .cpu();
  view.alpha = out.alpha.cpu();
  return view;
}

RenderedViewFiles rendered_view_files(const std::filesystem::path& dir, const std::string& name) {
  return {dir / "rgb" / (name + ".png"), dir / "depth" / (name + ".npy"),
          dir / "depth" / (name + ".png"), dir / "alpha" / (name + ".png")};
}

namespace {

// Returns how many pixels the 16-bit depth PNG clamps: the .npy beside it keeps their depth.
size_t write_rendered_view(const std::filesystem::path& dir, const std::string& name,
                           const RenderedView& view) {
  const RenderedViewFiles files = rendered_view_files(dir, name);
  const int height = int(view.depth.size(0)), width = int(view.depth.size(1));
  write_png(files.rgb, to_image8(view.image.unsqueeze(0)));
  const std::vector<float> depth = to_vector(view.depth);
  write_npy(files.depth_npy, depth, {size_t(height), size_t(width)});
  std::vector<uint16_t> depth16(depth.size());
  size_t clamped = 0;
  for (size_t i = 0; i < depth.size(); ++i) {
    const long units = std::lround(depth[i] * kDepthPngScale);
    clamped += units > 65535;
    depth16[i] = uint16_t(std::clamp(units, 0L, 65535L));
  }
  write_png16(files.depth_png, depth16, width, height);
  write_png(files.alpha, gray_image8(view.alpha));
  return clamped;
}

}  // namespace

double render_views_to(const std::filesystem::path& dir, const gs::GaussianModel& model,
                       const std::vector<Camera>& cameras, const std::array<float, 3>& background,
                       double scale) {
  require_render_memory(cameras, scale);
  // One untimed frame first: a process's first render pays for loading the GPU kernels and
  // growing the allocator's pools, which would otherwise count against the rendering speed.
  if (!cameras.empty()) render_view(model, cameras.front().scaled(scale), background);
  double render_seconds = 0;
  size_t clamped = 0;
  bool any_drawn = false;
  for (size_t i = 0; i < cameras.size(); ++i) {
    stop_if_interrupted("rendering");
    const Camera camera = cameras[i].scaled(scale);
    const Stopwatch watch;
    const RenderedView view = render_view(model, camera, background);
    render_seconds += watch.seconds();
    clamped += write_rendered_view(dir, camera.name, view);
    any_drawn = any_drawn || view.alpha.max().item<float>() >= 0.5f / 255;
    if ((i + 1) % 20 == 0 || i + 1 == cameras.size())
      fmt::print("rendered {}/{} views at {}x{}\n", i + 1, cameras.size(), camera.intrinsics.width,
                 camera.intrinsics.height);
  }
  // Blank views are written and timed as any others, but are seldom what was meant.
  if (!any_drawn && !cameras.empty())
    spdlog::warn(
        "every view rendered blank, the background alone: the model lies outside these cameras' "
        "views (another scene's cameras, or poses in another convention?), or none of its "
        "Gaussians can be drawn (zero rotations, scales that overflow)");
  if (clamped)
    fmt::print(
        "note: {} {} farther than {} scene units, the most a 16-bit depth PNG holds at x{}; "
        "depth/*.npy keeps their depth\n",
        clamped, clamped == 1 ? "pixel lies" : "pixels lie", 65535 / kDepthPngScale,
        kDepthPngScale);
  return cameras.empty() ? 0 : render_seconds / double(cameras.size());
}

double render_views_recorded(const std::filesystem::path& dir, const gs::GaussianModel& model,
                             const std::vector<Camera>& cameras,
                             const std::array<float, 3>& background, double scale,
                             nlohmann::json record) {
  std::vector<std::string> names;
  for (const Camera& camera : cameras) names.push_back(camera.name);
  require_render_memory(cameras, scale);  // before anything of the earlier render goes
  remove_earlier_render(dir, names);
  const Camera first = cameras.empty() ? Camera{} : cameras.front().scaled(scale);
  record["views"] = cameras.size();
  record["width"] = first.intrinsics.width;
  record["height"] = first.intrinsics.height;
  record["gaussians"] = model.size();
  record["rasterize_mode"] = model.antialiased ? "antialiased" : "classic";
  record["background"] = background;
  record["depth_png_scale"] = kDepthPngScale;
  record["names"] = names;
  record["finished"] = false;
  const std::filesystem::path path = dir / "render.json";
  write_file_atomically(path, record.dump(2) + "\n");
  const double seconds = render_views_to(dir, model, cameras, background, scale);
  record["seconds_per_view"] = seconds;
  record["fps"] = frames_per_second(seconds);
  record["finished"] = true;
  write_file_atomically(path, record.dump(2) + "\n");
  return seconds;
}

}  // namespace iesrgs::pipeline
