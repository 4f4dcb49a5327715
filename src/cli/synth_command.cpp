// iesrgs synth: the built-in synthetic scene, written as a NeRF-Synthetic dataset or (--format
// colmap) as a COLMAP capture.
#include <fmt/format.h>

#include <map>
#include <memory>
#include <string>

#include "cli/commands.hpp"
#include "cli/validators.hpp"
#include "core/progress.hpp"
#include "core/stopwatch.hpp"
#include "synth/dataset_writer.hpp"

namespace iesrgs::cli {

void add_synth_command(CLI::App& app) {
  auto* command = app.add_subcommand(
      "synth",
      "Render the built-in synthetic scene as a dataset with ground-truth depth (.npy): "
      "NeRF-Synthetic layout (RGBA PNGs, transforms_train/test.json) or a COLMAP capture");
  auto output = std::make_shared<std::string>();
  auto options = std::make_shared<synth::SynthOptions>();
  command
      ->add_option("-o,--output", *output,
                   "Directory to write the scene into; one holding a scene synth did not write "
                   "is refused")
      ->required()
      ->check(kNonEmptyPath);
  command->add_option("--size", options->size, "Image width and height in pixels")
      ->capture_default_str();
  command
      ->add_option("--views", options->train_views,
                   "Training views (upper hemisphere); with --format colmap, the views and "
                   "test views make one capture, of which every 8th image is held out")
      ->capture_default_str();
  command->add_option("--test-views", options->test_views, "Test views (a spiral between them)")
      ->capture_default_str();
  command->add_option("--seed", options->seed, "Picks layout, colours and patterns")
      ->capture_default_str()
      ->check(kNonNegative);  // -1 would wrap around to 2^64 - 1
  command->add_option("--samples", options->samples,
                      "Antialiasing samples per pixel, a square number (default: 16 up to 256 "
                      "px, 9 up to 512 px, 4 above)");
  const std::map<std::string, synth::SynthFormat> formats{{"blender", synth::SynthFormat::Blender},
                                                          {"colmap", synth::SynthFormat::Colmap}};
  command
      ->add_option("--format", options->format,
                   "blender: NeRF-Synthetic layout with separate test views; colmap: images/ "
                   "and sparse/0 with surface points as SfM points, every 8th image held out")
      ->transform(CLI::CheckedTransformer(formats, CLI::ignore_case))
      ->default_str("blender");
  command->callback([output, options] {
    const Stopwatch watch;
    synth::write_synth_dataset(*output, *options, [](int done, int total) {
      print_count_on_stderr("rendered views", size_t(done), size_t(total));
    });
    const std::string views =
        options->format == synth::SynthFormat::Colmap
            ? fmt::format("{} views (every 8th is held out for test)",
                          options->train_views + options->test_views)
            : fmt::format("{} train and {} test views", options->train_views, options->test_views);
    fmt::print("wrote {} of {}x{} to {} in {:.1f} s\n", views, options->size, options->size,
               *output, watch.seconds());
  });
}

}  // namespace iesrgs::cli
