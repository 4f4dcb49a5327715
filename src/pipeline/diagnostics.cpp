#include "pipeline/diagnostics.hpp"

#include <fmt/core.h>
#include <torch/torch.h>

#include <array>

#include "eval/mask_agreement.hpp"
#include "io/atomic_file.hpp"
#include "io/image.hpp"
#include "io/image_tensor.hpp"
#include "loss/fusion.hpp"
#include "priors/depth/depth_preview.hpp"

namespace iesrgs::pipeline {

namespace {

namespace fs = std::filesystem;

constexpr std::array<const char*, 8> kColumns = {"external",   "internal", "discrepancy", "mask",
                                                 "mask_check", "render",   "depth",       "truth"};

torch::Tensor gray_to_rgb(const torch::Tensor& map) {
  return map.clamp(0, 1).expand({3, -1, -1});
}

// M against the oracle mask: green where M hands the pixel to the internal image and that is the
// closer reference to the truth, red where it is not, gray where M keeps the external image but
// the internal one is closer.
torch::Tensor mask_check(const torch::Tensor& mask, const torch::Tensor& oracle) {
  const torch::Tensor right = (mask & oracle).to(torch::kFloat);
  const torch::Tensor wrong = (mask & ~oracle).to(torch::kFloat);
  const torch::Tensor missed = 0.35 * (~mask & oracle).to(torch::kFloat);
  return torch::stack({wrong + missed, right + missed, missed});
}

torch::Tensor preview_tensor(const torch::Tensor& depth) {
  const torch::Tensor inverse = torch::where(depth > 0, 1 / depth.clamp_min(1e-6), 0);
  return to_tensor(to_float(priors::depth::depth_preview(inverse)))[0];
}

// The view's pictures in kColumns order, undefined where the run lacks one.
std::array<torch::Tensor, kColumns.size()> columns(const DiagnosticView& v, double threshold) {
  std::array<torch::Tensor, kColumns.size()> out;
  out[0] = v.external_image;
  out[1] = v.internal_image;
  if (v.external_image.defined() && v.internal_image.defined()) {
    const torch::Tensor d = loss::discrepancy(v.internal_image, v.external_image);
    out[2] = gray_to_rgb(d / (2 * threshold));
    const torch::Tensor mask = d >= threshold;
    out[3] = gray_to_rgb(mask.to(torch::kFloat));
    if (v.truth.defined())
      out[4] = mask_check(mask, eval::oracle_mask(v.internal_image, v.external_image, v.truth));
  }
  out[5] = v.render;
  out[6] = preview_tensor(v.render_depth);
  out[7] = v.truth;
  return out;
}

void write_tensor_png(const fs::path& path, const torch::Tensor& rgb) {
  write_png(path, to_image8(rgb.unsqueeze(0)));
}

std::string html_page(const fs::path& dir, const std::vector<DiagnosticView>& views) {
  std::string html =
      "<!doctype html><meta charset=\"utf-8\"><title>IE-SRGS diagnostics</title>\n"
      "<style>img{width:100%}td,th{padding:2px;font:12px sans-serif}</style>\n<table><tr><th>view";
  for (const char* column : kColumns) html += fmt::format("<th>{}", column);
  for (const DiagnosticView& view : views) {
    html += fmt::format("\n<tr><th>{}", view.name);
    for (const char* column : kColumns) {
      const fs::path file = fs::path(view.name) / (std::string(column) + ".png");
      html += fs::exists(dir / file)
                  ? fmt::format("<td><img src=\"{}\" alt=\"{}\">", file.string(), column)
                  : std::string("<td>");
    }
  }
  return html + "\n</table>\n";
}

}  // namespace

void write_diagnostics(const fs::path& dir, const std::vector<DiagnosticView>& views,
                       double threshold) {
  if (views.empty()) return;
  std::vector<torch::Tensor> rows;
  for (const DiagnosticView& view : views) {
    const auto pictures = columns(view, threshold);
    const torch::Tensor blank = torch::zeros_like(view.render);
    std::vector<torch::Tensor> row;
    for (size_t c = 0; c < kColumns.size(); ++c) {
      const fs::path file = dir / view.name / (std::string(kColumns[c]) + ".png");
      if (pictures[c].defined()) {
        write_tensor_png(file, pictures[c]);
      } else {
        std::error_code ignored;  // an earlier run's picture would pass for this run's
        fs::remove(file, ignored);
      }
      row.push_back(pictures[c].defined() ? pictures[c] : blank);
    }
    rows.push_back(torch::cat(row, 2));
  }
  // Views of other sizes than the first cannot share the sheet's grid.
  std::vector<torch::Tensor> same_size;
  for (const torch::Tensor& row : rows)
    if (row.sizes() == rows.front().sizes()) same_size.push_back(row);
  write_tensor_png(dir / "contact_sheet.png", torch::cat(same_size, 1));
  write_file_atomically(dir / "contact_sheet.html", html_page(dir, views));
  fmt::print("diagnostics of {} views in {}\n", views.size(), dir.string());
}

}  // namespace iesrgs::pipeline
