#pragma once
// Stage 4: render the test views at HR and score the 8-bit renders, as written to disk, against
// the ground truth (PSNR, SSIM, and LPIPS when its weights are at hand).
#include <array>
#include <filesystem>
#include <string>
#include <vector>

#include "eval/lpips.hpp"
#include "eval/metrics.hpp"
#include "gs/model.hpp"
#include "io/view_images.hpp"

namespace iesrgs::pipeline {

struct Evaluation {
  eval::MetricsReport report;   // empty without ground truth
  double seconds_per_view = 0;  // rendering alone
};

// Renders the test views `cameras` (held out as every `test_every`-th where the scene has no
// split) into <dir>/{rgb,depth,alpha}, recorded in <dir>/render.json (render_views_recorded) for
// eval; with `truth`, scores every render against truth->rgb(camera), with LPIPS when `lpips`
// holds the metric, and writes <dir>/metrics.json and .csv.
Evaluation render_and_evaluate(const gs::GaussianModel& model, const std::vector<Camera>& cameras,
                               int test_every, const std::array<float, 3>& background,
                               ViewImages* truth, const eval::LoadedLpips& lpips,
                               const std::filesystem::path& dir);

}  // namespace iesrgs::pipeline
