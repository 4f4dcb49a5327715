#pragma once
// Stage 1 of IE-SRGS, external knowledge: every training view's low-resolution image through a
// pre-trained 2D super-resolution network (E_image), and E_image through a monocular depth
// network (E_depth). Results are cached per view with a fingerprint of everything they depend
// on, so a rerun recomputes only what changed and an interrupted run resumes.
#include <filesystem>
#include <string>
#include <vector>

#include "io/scene.hpp"
#include "io/view_images.hpp"
#include "priors/sr/tiling.hpp"

namespace iesrgs::pipeline {

struct ExternalOptions {
  std::string sr_model = "auto";     // "auto": see resolve_sr_model
  std::filesystem::path sr_weights;  // empty: the model's default location
  int scale = 4;
  priors::sr::TileOptions tiles = priors::sr::kDefaultTiles;
  std::string depth_model = "none";  // "none" turns the external depth prior off
  std::filesystem::path depth_weights;
};

struct ExternalView {
  std::string name;
  std::filesystem::path image;  // <dir>/image/<name>.png, E_image
  std::filesystem::path depth;  // <dir>/depth/<name>.npy, E_depth; empty without a depth model
  // What computing it took when it ran (<dir>/seconds.json), from the view computed before it or
  // the stage's start: the network's loading and the checks of cached views between included. 0
  // for a view cached before the time was recorded.
  double seconds = 0;
};

// Replaces "auto" by the best SR model at hand for the scale (priors::sr::auto_sr_model), saying
// which when `announce`.
void resolve_sr_model(ExternalOptions& options, bool announce);

// Runs the stage for the training cameras of `scene` (the low-resolution input) into `dir`,
// printing progress, and returns one entry per training view in scene order. The cache record is
// <dir>/external.json, updated after every view.
std::vector<ExternalView> run_external_stage(const Scene& scene, ViewImages& images,
                                             const ExternalOptions& options,
                                             const std::filesystem::path& dir);

// Whether every training view's outputs in `dir` are cached for these options and intact, as
// run_external_stage would find them.
bool external_stage_current(const Scene& scene, ViewImages& images, const ExternalOptions& options,
                            const std::filesystem::path& dir);

}  // namespace iesrgs::pipeline
