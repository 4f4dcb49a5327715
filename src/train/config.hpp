#pragma once
// Every hyper-parameter of a training run, the presets that fill them in, and their JSON form
// (the file saved beside the outputs, and the config files users pass in).
#include <array>
#include <nlohmann/json_fwd.hpp>

#include <cstdint>
#include <string>
#include <vector>

#include "gs/optimizer.hpp"
#include "loss/photometric.hpp"

namespace iesrgs::train {

struct TrainConfig {
  std::string preset = "paper";
  int64_t iterations = 30000;
  int views_per_iteration = 1;  // MVGS's K: distinct random views summed into one step
  uint64_t seed = 0;
  double dssim_weight = loss::kDssimWeight;  // loss = (1 - w) * L1 + w * D-SSIM per view

  int max_sh_degree = 3;
  int64_t sh_increase_every = 1000;

  int64_t densify_from = 500, densify_until = 15000, densify_every = 100;
  int64_t opacity_reset_every = 3000;
  double grad_threshold = 2e-4;
  bool absolute_gradients = false;  // AbsGS's; wants a larger grad_threshold (gs/densify.hpp)
  double percent_dense = 0.01;
  double min_opacity = 0.005;
  // Large-splat pruning after the first opacity reset; 0: off. 3DGS and Mip-Splatting pass a
  // 20-pixel limit too, but zero the radii it tests before testing them: only the world-size
  // rule prunes there, so that is the default.
  float max_screen_size = 0;          // pixels, of the extent where alpha reaches 1/255
  double max_world_size = 0.1;        // x the scene extent
  int64_t filter_update_every = 100;  // Mip-Splatting 3D filter, once densification has stopped
  // Densification grows the model no further than this (largest gradients first); 0: no cap
  // but the available memory.
  int64_t max_gaussians = 0;

  gs::LearningRates learning_rates;

  std::string init = "auto";  // auto (SfM points when the scene has some, else random), random
  int random_points = 100000;
  float random_extent = 0;  // half-size of their cube around the origin; 0: from the scene
                            // (train::random_box)

  int64_t checkpoint_every = 1000;
  int64_t test_every = 1000;  // iterations between test PSNR reports; 0 = never
  int test_views = 10;        // test views in those reports (evenly spaced); 0 = all
  int64_t log_every = 10;     // iterations between train_log.csv rows (test reports, the last
                              // iteration and an interruption always get one)
};

// A built-in preset: "paper" (the 30k-iteration schedule of 3DGS and Mip-Splatting, for GPUs), or
// "cpu" and "fast", which shorten the schedule to 10k and 3k iterations and leave the pruning of
// world-large Gaussians off ("fast" also reports and checkpoints every 500 iterations). The
// preset, with its schedule (densification window, opacity reset, SH steps, position decay)
// rescaled to `iterations` when that is positive. Throws Error for an unknown name.
TrainConfig make_preset(const std::string& name, int64_t iterations = 0);

// Rescales the schedule (densification window, opacity resets, SH steps, position decay) so that
// it spans `iterations`; the intervals of densification, the 3D filter, checkpoints and test
// reports stay.
void rescale_schedule(TrainConfig& config, int64_t iterations);

// The fields that say how a training reports and saves itself, not what it learns: --resume takes
// new values of them, and a cached stage is not trained again for them.
inline constexpr std::array<const char*, 4> kReportingFields = {"checkpoint_every", "test_every",
                                                                "test_views", "log_every"};

nlohmann::json to_json(const TrainConfig& config);
// The fields but kReportingFields in which `to` differs from `from`, each as "key <to's value>
// instead of <from's>".
std::vector<std::string> config_changes(const TrainConfig& from, const TrainConfig& to);
// Overrides the fields present in `json`; unknown keys and wrong types are errors naming `origin`.
void apply_json(TrainConfig& config, const nlohmann::json& json, const std::string& origin);
// "key=value" overrides from the command line (value parsed as JSON, else taken as a string),
// given with <option_prefix>set; errors name that option.
void apply_assignment(TrainConfig& config, const std::string& assignment,
                      const std::string& option_prefix = "--");

// Throws Error naming the first inconsistent field.
void validate(const TrainConfig& config);

}  // namespace iesrgs::train
