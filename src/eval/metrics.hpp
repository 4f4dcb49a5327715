#pragma once
// Image-quality metrics as 3D super-resolution papers report them: PSNR over all pixels and
// channels, and SSIM with an 11x11 Gaussian window (sigma 1.5), both on RGB in [0, 1].
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "io/image.hpp"

namespace iesrgs::eval {

// Both images RGB (HWC) of the same size; throws Error otherwise.
double psnr(const Image& image, const Image& reference);
// PSNR of a mean squared error on values in [0, 1]; infinite for a perfect match.
double psnr_from_mse(double mse);
double ssim(const Image& image, const Image& reference);

struct ViewMetrics {
  std::string name;
  double psnr = 0, ssim = 0;
  std::optional<double> lpips;
};

class Lpips;
struct LoadedLpips;

// Scores of one render against its reference (both RGB of the same size); LPIPS when given and
// the images are not smaller than its network takes.
ViewMetrics measure_view(const std::string& name, const Image& render, const Image& reference,
                         const Lpips* lpips);

// What a report says of LPIPS: the net's name, or why some or all of `views` have none.
std::string lpips_status(const LoadedLpips& lpips, const std::vector<ViewMetrics>& views);

struct MetricsReport {
  std::vector<ViewMetrics> views;
  std::string lpips_status;           // the net's name, or why LPIPS is unavailable
  std::vector<std::string> unscored;  // views of the split with no render: not in the mean

  ViewMetrics mean() const;  // name "mean"; lpips only when every view has it
};

// <path>.json (per view and mean) and <path>.csv (one row per view, then the mean), atomically.
void write_report(const std::filesystem::path& path_without_extension, const MetricsReport& report);

}  // namespace iesrgs::eval
