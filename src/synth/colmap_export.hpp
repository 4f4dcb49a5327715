#pragma once
// The synthetic scene as a COLMAP capture: opaque photos in images/ and a sparse model in
// sparse/0 whose points stand in for structure-from-motion points (surface samples with their
// colours), so the COLMAP path, SfM initialization included, can run without COLMAP.
#include <filesystem>
#include <string>

#include "io/colmap.hpp"
#include "synth/camera_path.hpp"
#include "synth/renderer.hpp"

namespace iesrgs::synth {

class ColmapExport {
 public:
  ColmapExport(const RenderSettings& settings, int points_per_view);

  // Adds one view's pose and a sparse set of its surface points (pixels fully covered by the
  // scene, unprojected with the ground-truth depth, coloured as rendered).
  void add_view(const CameraPose& pose, const RenderedView& view, const std::string& name);
  // Writes sparse/0/{cameras,images,points3D}.bin under `dir`.
  void write(const std::filesystem::path& dir) const;

 private:
  RenderSettings settings_;
  int points_per_view_;
  ColmapModel model_;
};

}  // namespace iesrgs::synth
