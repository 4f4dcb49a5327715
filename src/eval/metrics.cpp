#include "eval/metrics.hpp"

#include <fmt/core.h>

#include <algorithm>
#include <cmath>
#include <nlohmann/json.hpp>

#include "core/error.hpp"
#include "eval/lpips.hpp"
#include "io/atomic_file.hpp"
#include "io/image_tensor.hpp"
#include "loss/ssim.hpp"

namespace iesrgs::eval {

namespace {

void check_same_shape(const Image& image, const Image& reference) {
  if (image.channels != 3 || reference.channels != 3)
    fail("metrics need RGB images, got {} and {} channels", image.channels, reference.channels);
  if (image.width != reference.width || image.height != reference.height)
    fail("image is {}x{} but its reference is {}x{}", image.width, image.height, reference.width,
         reference.height);
}

nlohmann::json to_json(const ViewMetrics& m) {
  nlohmann::json json = {{"name", m.name}, {"psnr", m.psnr}, {"ssim", m.ssim}};
  json["lpips"] = m.lpips ? nlohmann::json(*m.lpips) : nlohmann::json(nullptr);
  return json;
}

// A view's name as one CSV field (RFC 4180): quoted, quotes doubled, when it holds a comma, a
// quote or a line break, which file names may.
std::string csv_field(const std::string& text) {
  if (text.find_first_of(",\"\r\n") == std::string::npos) return text;
  std::string quoted = "\"";
  for (const char c : text) quoted += c == '"' ? std::string("\"\"") : std::string(1, c);
  return quoted + "\"";
}

std::string csv_row(const ViewMetrics& m) {
  return fmt::format("{},{:.6f},{:.6f},{}\n", csv_field(m.name), m.psnr, m.ssim,
                     m.lpips ? fmt::format("{:.6f}", *m.lpips) : "");
}

}  // namespace

double psnr(const Image& image, const Image& reference) {
  check_same_shape(image, reference);
  double sum = 0;
  for (size_t i = 0; i < image.data.size(); ++i) {
    const double d = double(image.data[i]) - double(reference.data[i]);
    sum += d * d;
  }
  return psnr_from_mse(sum / double(image.data.size()));
}

double psnr_from_mse(double mse) {
  return mse > 0 ? -10.0 * std::log10(mse) : INFINITY;
}

double ssim(const Image& image, const Image& reference) {
  check_same_shape(image, reference);
  const torch::Tensor x = to_tensor(image), y = to_tensor(reference);  // planar copies
  return loss::ssim<float>(x.data_ptr<float>(), y.data_ptr<float>(), {image.width, image.height, 3},
                           nullptr, nullptr);
}

ViewMetrics measure_view(const std::string& name, const Image& render, const Image& reference,
                         const Lpips* lpips) {
  std::optional<double> perceptual;
  if (lpips && std::min(render.width, render.height) >= lpips->min_size())
    perceptual = lpips->distance(to_tensor(render), to_tensor(reference));
  return {name, psnr(render, reference), ssim(render, reference), perceptual};
}

std::string lpips_status(const LoadedLpips& lpips, const std::vector<ViewMetrics>& views) {
  const bool every_view = std::all_of(
      views.begin(), views.end(), [](const ViewMetrics& view) { return view.lpips.has_value(); });
  if (!lpips.get() || every_view) return lpips.status;
  const int size = lpips.get()->min_size();
  return fmt::format("{}: not computed for views under {}x{} pixels, the network's smallest",
                     lpips.status, size, size);
}

ViewMetrics MetricsReport::mean() const {
  ViewMetrics mean{"mean", 0, 0, 0.0};
  for (const ViewMetrics& v : views) {
    mean.psnr += v.psnr;
    mean.ssim += v.ssim;
    if (v.lpips && mean.lpips)
      *mean.lpips += *v.lpips;
    else
      mean.lpips.reset();
  }
  const double n = views.empty() ? 1.0 : double(views.size());
  mean.psnr /= n;
  mean.ssim /= n;
  if (mean.lpips) *mean.lpips /= n;
  if (views.empty()) mean.lpips.reset();
  return mean;
}

void write_report(const std::filesystem::path& base, const MetricsReport& report) {
  const ViewMetrics mean = report.mean();
  nlohmann::json json = {
      {"mean", to_json(mean)}, {"views", nlohmann::json::array()}, {"lpips", report.lpips_status}};
  for (const ViewMetrics& v : report.views) json["views"].push_back(to_json(v));
  if (!report.unscored.empty()) json["unscored_views"] = report.unscored;
  // The earlier pair goes first: an eval stopped as it renames its two files leaves one, not a
  // new report beside an old one.
  for (const char* extension : {".json", ".csv"}) {
    remove_stale_temporaries_of(base.string() + extension);  // an eval killed mid-write's
    remove_earlier_output(base.string() + extension, "left by an earlier eval");
  }
  std::string csv = "name,psnr,ssim,lpips\n";
  for (const ViewMetrics& v : report.views) csv += csv_row(v);
  csv += csv_row(mean);
  write_files_atomically(
      {{base.string() + ".json", json.dump(2) + "\n"}, {base.string() + ".csv", csv}});
}

}  // namespace iesrgs::eval
