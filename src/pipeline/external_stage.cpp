#include "pipeline/external_stage.hpp"

#include <fmt/core.h>
#include <torch/torch.h>

#include <nlohmann/json.hpp>

#include "core/error.hpp"
#include "core/interrupt.hpp"
#include "core/progress.hpp"
#include "core/stopwatch.hpp"
#include "io/atomic_file.hpp"
#include "io/file_digest.hpp"
#include "io/image.hpp"
#include "io/image_tensor.hpp"
#include "pipeline/stage_record.hpp"
#include "priors/depth/depth_files.hpp"
#include "priors/depth/depth_net.hpp"
#include "priors/sr/esrgan.hpp"
#include "priors/sr/registry.hpp"
#include "priors/sr/sr_net.hpp"

namespace iesrgs::pipeline {

namespace {

namespace fs = std::filesystem;

// What the SR network computes besides its name and scale: its checkpoint (the default one when
// none is given), or an ESRGAN package's model folder for this scale.
std::string sr_weights_digest(const ExternalOptions& o) {
  const std::string esrgan = "esrgan-";
  if (o.sr_model.rfind(esrgan, 0) == 0)
    return directory_digest(
        priors::sr::esrgan_model_dir(o.sr_model.substr(esrgan.size()), o.scale, o.sr_weights));
  if (!o.sr_weights.empty() || o.sr_model == "bicubic") return file_digest(o.sr_weights);
  return file_digest(priors::sr::default_sr_weights(o.sr_model, o.scale));
}

// Everything one view's outputs depend on besides the view itself.
std::string external_stage_identity(const ExternalOptions& o) {
  return fmt::format("sr={} x{} tile={}/{} weights={} | depth={} weights={}", o.sr_model, o.scale,
                     o.tiles.tile, o.tiles.overlap, sr_weights_digest(o), o.depth_model,
                     // Without a depth model its weights are unused: naming them changes nothing.
                     file_digest(o.depth_model == "none" ? fs::path() : o.depth_weights));
}

std::string view_fingerprint(const std::string& stage, const ViewImages& images,
                             const Camera& camera) {
  const Scene& scene = images.scene();
  std::string text =
      fmt::format("{} | {} {}x{} /{} bg {},{},{}", stage, images.source_digest(camera),
                  camera.intrinsics.width, camera.intrinsics.height, scene.downscale,
                  scene.background[0], scene.background[1], scene.background[2]);
  // A distorted view is undistorted before it is upscaled: its lens shapes the input too.
  if (const Distortion& d = camera.distortion; d.any()) {
    const Intrinsics& k = camera.intrinsics;
    text += fmt::format(" | lens {} {} {} {} {} {} {} {}", k.fx, k.fy, k.cx, k.cy, d.k1, d.k2, d.p1,
                        d.p2) +
            d.terms_beyond_opencv();
  }
  return bytes_digest(text);
}

ExternalView external_view(const Camera& camera, const ExternalOptions& options,
                           const fs::path& dir) {
  return {camera.name, dir / "image" / (camera.name + ".png"),
          options.depth_model == "none" ? fs::path() : dir / "depth" / (camera.name + ".npy")};
}

// Whether the record holds `view` under `fingerprint` and its files are whole.
bool view_cached(const nlohmann::json& record, const std::string& fingerprint,
                 const ExternalView& view, const Camera& camera, int scale) {
  if (record.value(view.name, "") != fingerprint) return false;
  const Intrinsics upscaled = camera.intrinsics.scaled(scale);
  if (cached_view_intact(view.image, view.depth, upscaled.width, upscaled.height)) return true;
  fmt::print("external {}: the cached output is damaged or missing\n", view.name);
  return false;
}

// The external networks, loaded at the first view that needs them: a rerun that finds every view
// cached reads no weights.
class ExternalNets {
 public:
  explicit ExternalNets(const ExternalOptions& options) : options_(options) {}

  // E_image of `rgb` into view.image, and E_depth of it into view.depth unless the depth model
  // is none.
  void compute(const torch::Tensor& rgb, const ExternalView& view) {
    if (!sr_) {
      sr_ = priors::sr::make_sr_net(options_.sr_model, options_.sr_weights, options_.scale);
      depth_ = priors::depth::make_depth_net(options_.depth_model, options_.depth_weights);
    }
    write_png(view.image, to_image8(priors::sr::upscale_tiled(*sr_, rgb, options_.tiles)));
    if (!depth_) return;
    // Depth of E_image as the model saw it: the 8-bit image written above.
    const torch::Tensor seen = to_tensor(to_float(read_image8(view.image)));
    priors::depth::write_depth_outputs(depth_->predict(seen),
                                       priors::depth::depth_job(view.image, view.depth));
  }

 private:
  const ExternalOptions& options_;
  std::unique_ptr<priors::sr::SrNet> sr_;
  std::unique_ptr<priors::depth::DepthNet> depth_;
};

}  // namespace

void resolve_sr_model(ExternalOptions& options, bool announce) {
  if (options.sr_model != "auto") return;
  options.sr_model = priors::sr::auto_sr_model(options.scale);
  if (announce) fmt::print("SR prior: {} (--sr-model auto)\n", options.sr_model);
}

std::vector<ExternalView> run_external_stage(const Scene& scene, ViewImages& images,
                                             const ExternalOptions& options, const fs::path& dir) {
  if (options.sr_model == "auto") fail("run_external_stage: resolve the SR model first");
  const std::string stage = external_stage_identity(options);
  const fs::path record_path = dir / "external.json", seconds_path = dir / "seconds.json";
  nlohmann::json record = read_stage_record(record_path);
  nlohmann::json seconds_of = read_stage_record(seconds_path);
  ExternalNets nets(options);

  const std::vector<const Camera*> cameras = scene.split(Split::Train);
  std::vector<ExternalView> views;
  size_t computed = 0;
  const Stopwatch watch;
  Stopwatch since_computed;  // the time a computed view took, from the one before
  for (size_t i = 0; i < cameras.size(); ++i) {
    const Camera& camera = *cameras[i];
    ExternalView& view = views.emplace_back(external_view(camera, options, dir));
    const std::string fingerprint = view_fingerprint(stage, images, camera);
    if (view_cached(record, fingerprint, view, camera, options.scale)) {
      const nlohmann::json recorded = seconds_of.value(camera.name, nlohmann::json());
      if (recorded.is_number()) view.seconds = recorded.get<double>();
      continue;
    }
    stop_if_interrupted("the external stage");
    // Forget the view's old entry first: a run killed between the writes below must not leave
    // new files under it, which a later run with the old settings would take for its own.
    if (record.erase(camera.name)) write_file_atomically(record_path, record.dump(1) + "\n");
    nets.compute(to_tensor(*images.rgb(camera)), view);
    record[camera.name] = fingerprint;
    write_file_atomically(record_path, record.dump(1) + "\n");
    view.seconds = since_computed.lap();
    seconds_of[camera.name] = view.seconds;
    write_file_atomically(seconds_path, seconds_of.dump(1) + "\n");
    ++computed;
    const double seconds = watch.seconds();
    // The views left may be cached: the estimate errs long.
    fmt::print("external {}/{} {}: {:.2f} s per view, ETA {}\n", i + 1, cameras.size(), camera.name,
               seconds / double(computed),
               format_eta(computed, computed + cameras.size() - i - 1, seconds));
    std::fflush(stdout);
  }
  fmt::print("external stage: {} views computed, {} reused from {}\n", computed,
             cameras.size() - computed, dir.string());
  return views;
}

bool external_stage_current(const Scene& scene, ViewImages& images, const ExternalOptions& options,
                            const fs::path& dir) {
  const std::string stage = external_stage_identity(options);
  const nlohmann::json record = read_stage_record(dir / "external.json");
  for (const Camera* camera : scene.split(Split::Train))
    if (!view_cached(record, view_fingerprint(stage, images, *camera),
                     external_view(*camera, options, dir), *camera, options.scale))
      return false;
  return true;
}

}  // namespace iesrgs::pipeline
