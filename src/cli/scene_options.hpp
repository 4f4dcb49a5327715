#pragma once
// Options every command that reads a scene shares (--downscale, --background, --test-every).
#include <CLI/CLI.hpp>

#include <string>

#include "io/scene.hpp"

namespace iesrgs::cli {

struct SceneArgs {
  std::string path;
  SceneOptions options;
  std::string background = "white";

  // Registers the positional scene path and the loading options on `command`.
  void add_to(CLI::App& command);
  // Validated SceneOptions (parses --background).
  SceneOptions resolved() const;
};

}  // namespace iesrgs::cli
