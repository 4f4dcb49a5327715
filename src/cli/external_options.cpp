#include "cli/external_options.hpp"

#include "cli/shared_options.hpp"

namespace iesrgs::cli {

void add_external_options(CLI::App& command, pipeline::ExternalOptions& o) {
  command.add_option("--sr-model", o.sr_model, "2D SR backend (see iesrgs upscale)")
      ->capture_default_str();
  command.add_option("--sr-weights", o.sr_weights, "SR checkpoint (default: the model's own)");
  add_tile_options(command, o.tiles);
  command
      .add_option("--depth-model", o.depth_model,
                  "none, or depth-anything-v2[-vits|-vitb|-vitl] (needs --depth-weights)")
      ->capture_default_str();
  command.add_option("--depth-weights", o.depth_weights, "Depth Anything V2 checkpoint");
}

}  // namespace iesrgs::cli
