#include "cli/device_option.hpp"

#include <fmt/core.h>

#include "core/device.hpp"

namespace iesrgs::cli {

void add_device_option(CLI::App& command, std::string& device) {
  command
      .add_option(
          "--device", device,
          "Run on the cpu, on a cuda GPU, or auto: the GPU when this build and machine have "
          "one")
      ->check(CLI::IsMember({"cpu", "cuda", "auto"}))
      ->capture_default_str();
}

void use_device(const std::string& device) {
  set_compute_device(parse_device(device));
  fmt::print("device: {}\n", describe_device(compute_device()));
}

}  // namespace iesrgs::cli
