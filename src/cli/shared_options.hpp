#pragma once
// Options that several commands share, each with one help text and one check.
#include <CLI/CLI.hpp>

#include <string>
#include <vector>

#include "priors/sr/tiling.hpp"

namespace iesrgs::cli {

// Adds --device cpu|cuda|auto (default auto) to `command`, stored in `device`: where the tensors
// and the kernels of the commands that compute (train, render, the networks) run.
void add_device_option(CLI::App& command, std::string& device);

// Adds --lpips alex|vgg|vgg-3dgs|none, the LPIPS backbone of the evaluations, stored in `backbone`.
void add_lpips_option(CLI::App& command, std::string& backbone);

// Adds --background, the gray level in [0, 1] that the networks' commands composite transparent
// pixels over, stored in `gray`.
void add_gray_background_option(CLI::App& command, float& gray);

// Adds --tile and --tile-overlap, how the SR networks' commands cut an image, stored in `tiles`.
void add_tile_options(CLI::App& command, priors::sr::TileOptions& tiles);

// The options that set a training parameter of their own, which a --set may set again.
struct TrainingParameterOptions {
  const CLI::Option* iterations = nullptr;
  const CLI::Option* views_per_iteration = nullptr;
  const CLI::Option* seed = nullptr;
};

// Throws Error when one of `options` was given and one of `assignments`, the values of
// `set_flag`, sets the same parameter: which of the two should win would be a guess.
void refuse_sets_beside_options(const TrainingParameterOptions& options,
                                const std::vector<std::string>& assignments,
                                const std::string& set_flag);

// Makes `device` this process's compute device (core/device.hpp) and says which it is. Throws
// Error when it names a GPU this build or machine cannot use.
void use_device(const std::string& device);

}  // namespace iesrgs::cli
