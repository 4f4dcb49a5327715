#pragma once
// --device on the commands that compute (train, render, the networks): where the tensors and the
// kernels run.
#include <CLI/CLI.hpp>

#include <string>

namespace iesrgs::cli {

// Adds --device cpu|cuda|auto (default auto) to `command`, stored in `device`.
void add_device_option(CLI::App& command, std::string& device);

// Makes `device` this process's compute device (core/device.hpp) and says which it is. Throws
// Error when it names a GPU this build or machine cannot use.
void use_device(const std::string& device);

}  // namespace iesrgs::cli
