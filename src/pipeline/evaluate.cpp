#include "pipeline/evaluate.hpp"

#include "io/image.hpp"
#include "pipeline/render_views.hpp"

namespace iesrgs::pipeline {

Evaluation render_and_evaluate(const gs::GaussianModel& model, const std::vector<Camera>& cameras,
                               int test_every, const std::array<float, 3>& background,
                               ViewImages* truth, const eval::LoadedLpips& lpips,
                               const std::filesystem::path& dir) {
  Evaluation evaluation;
  evaluation.seconds_per_view = render_views_recorded(
      dir, model, cameras, background, 1.0, {{"split", "test"}, {"test_every", test_every}});
  if (!truth) return evaluation;
  eval::MetricsReport& report = evaluation.report;
  for (const Camera& camera : cameras) {
    const Image render = to_float(read_image8(rendered_view_files(dir, camera.name).rgb));
    report.views.push_back(
        eval::measure_view(camera.name, render, *truth->rgb(camera), lpips.get()));
  }
  report.lpips_status = eval::lpips_status(lpips, report.views);
  eval::write_report(dir / "metrics", report);
  return evaluation;
}

}  // namespace iesrgs::pipeline
