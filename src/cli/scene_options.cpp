#include "cli/scene_options.hpp"

#include "cli/validators.hpp"
#include "core/error.hpp"

namespace iesrgs::cli {

void SceneArgs::add_to(CLI::App& command, const std::string& what) {
  command.add_option("scene", path, what)->required();
  command
      .add_option("--downscale", options.downscale,
                  "Load images at 1/k resolution: <images>_<k>/ when present, else a "
                  "PIL-compatible bicubic resize")
      ->check(kPositive)
      ->capture_default_str();
  command
      .add_option("--background", background,
                  "Background behind the model and under RGBA images: white, black, r,g,b in "
                  "[0,1], or auto (white for NeRF Synthetic scenes, black for captures, as 3DGS)")
      ->capture_default_str();
  command
      .add_option("--test-every", options.test_every,
                  "Hold out every k-th image for test when the format has no test split")
      ->check(kPositive)
      ->capture_default_str();
}

SceneOptions SceneArgs::resolved() const {
  SceneOptions resolved = options;
  if (background == "auto") {
    resolved.background.reset();
  } else if (background == "white") {
    resolved.background = {1, 1, 1};
  } else if (background == "black") {
    resolved.background = {0, 0, 0};
  } else {
    float r, g, b;
    char tail;
    if (std::sscanf(background.c_str(), "%f,%f,%f%c", &r, &g, &b, &tail) != 3)
      fail("--background: expected auto, white, black or r,g,b, got '{}'", background);
    for (float channel : {r, g, b})
      if (!(channel >= 0 && channel <= 1))
        fail("--background: each of r,g,b must be in [0, 1], got '{}'", background);
    resolved.background = {r, g, b};
  }
  return resolved;
}

}  // namespace iesrgs::cli
