#include "cli/shared_options.hpp"

#include <fmt/core.h>

#include "cli/validators.hpp"
#include "core/device.hpp"
#include "core/error.hpp"

namespace iesrgs::cli {

void add_device_option(CLI::App& command, std::string& device) {
  command
      .add_option(
          "--device", device,
          "Run on the cpu, on a cuda GPU, or auto: the GPU when this build and machine have "
          "one")
      ->check(CLI::IsMember({"cpu", "cuda", "auto"}))
      ->capture_default_str();
}

void add_lpips_option(CLI::App& command, std::string& backbone) {
  command
      .add_option("--lpips", backbone,
                  "LPIPS backbone: alex, vgg, vgg-3dgs (VGG given [0, 1] images, as 3DGS's and "
                  "Mip-Splatting's metrics.py) or none. A backbone's torchvision checkpoint is "
                  "looked up in $IESRGS_WEIGHTS_DIR, else in torchvision's download cache "
                  "(hub/checkpoints under $TORCH_HOME, $XDG_CACHE_HOME/torch or ~/.cache/torch)")
      ->check(CLI::IsMember({"alex", "vgg", "vgg-3dgs", "none"}))
      ->capture_default_str();
}

void add_gray_background_option(CLI::App& command, float& gray) {
  command
      .add_option("--background", gray,
                  "Gray level in [0, 1] that transparent pixels are composited over")
      ->check(kUnitInterval)
      ->capture_default_str();
}

void add_tile_options(CLI::App& command, priors::sr::TileOptions& tiles) {
  command
      .add_option("--tile", tiles.tile,
                  "SR tile side in input pixels, 0 for the whole image at once")
      ->capture_default_str()
      ->check(kNonNegative);
  command
      .add_option("--tile-overlap", tiles.overlap,
                  "Input pixels shared by neighbouring SR tiles, cross-faded")
      ->capture_default_str()
      ->check(kNonNegative);
}

void refuse_sets_beside_options(const TrainingParameterOptions& options,
                                const std::vector<std::string>& assignments,
                                const std::string& set_flag) {
  for (const auto& [option, key] : {std::pair{options.iterations, "iterations"},
                                    std::pair{options.views_per_iteration, "views_per_iteration"},
                                    std::pair{options.seed, "seed"}}) {
    if (option->count() == 0) continue;
    // The key as apply_assignment reads it: everything before the first '=', untrimmed.
    const std::string prefix = std::string(key) + "=";
    for (const std::string& assignment : assignments)
      if (assignment.rfind(prefix, 0) == 0)
        fail("{} and {} {} both set {}: give one of them", option->get_name(), set_flag, assignment,
             key);
  }
}

void use_device(const std::string& device) {
  set_compute_device(parse_device(device));
  fmt::print("device: {}\n", describe_device(compute_device()));
}

}  // namespace iesrgs::cli
