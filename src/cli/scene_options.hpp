#pragma once
// Options every command that reads a scene shares (--downscale, --background, --test-every).
#include <CLI/CLI.hpp>

#include <string>

#include "io/scene.hpp"

namespace iesrgs::cli {

struct SceneArgs {
  std::string path;
  SceneOptions options;
  std::string background = "auto";

  // Registers the positional scene path (described by `what`, the scene formats by default) and
  // the loading options on `command`.
  void add_to(CLI::App& command, const std::string& what = kSceneHelp);

  static constexpr const char* kSceneHelp =
      "Scene: a folder with sparse/0 or sparse/ (COLMAP), transforms_train.json (NeRF Synthetic) "
      "or transforms.json (nerfstudio / instant-ngp), looked for in that order, or a "
      "transforms.json file";
  // Validated SceneOptions (parses --background).
  SceneOptions resolved() const;
};

}  // namespace iesrgs::cli
