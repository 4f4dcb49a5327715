#pragma once
// Pictures of the fusion stage for a person to look at: per training view the external and
// internal images, their discrepancy D and mask M, where M is right (benchmarks), and the HR
// model's render and depth, plus one contact sheet of them all (PNG and an HTML page with column
// titles).
#include <torch/types.h>

#include <filesystem>
#include <string>
#include <vector>

namespace iesrgs::pipeline {

struct DiagnosticView {
  std::string name;
  torch::Tensor external_image;  // (3, H, W); undefined when the run has none
  torch::Tensor internal_image;  // (3, H, W); undefined when the run has none
  torch::Tensor render;          // (3, H, W) the HR model at this view
  torch::Tensor render_depth;    // (H, W) its expected depth, 0 where nothing is drawn
  torch::Tensor truth;           // (3, H, W) HR ground truth; undefined for a user's LR capture
};

// <dir>/<name>/{external,internal,discrepancy,mask,mask_check,render,depth,truth}.png (those that
// exist; discrepancy is D / (2 T) in gray, mask white where the internal image is used,
// mask_check M against the truth: green where M picks the internal image and it is the closer
// reference, red where it is not, gray where M misses a pixel the internal image is closer at;
// depth the inverse depth in false color), <dir>/contact_sheet.png (a row per view, columns in
// that order, black where missing) and <dir>/contact_sheet.html.
void write_diagnostics(const std::filesystem::path& dir, const std::vector<DiagnosticView>& views,
                       double threshold);

}  // namespace iesrgs::pipeline
