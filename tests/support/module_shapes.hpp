#pragma once
// Parameter names and shapes, to check a module against the official layout that a fixture's
// names file records ("name dim dim ..." per line, written from the authors' state_dict()).
#include <gtest/gtest.h>
#include <torch/torch.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "priors/state_dict.hpp"

namespace iesrgs::testing {

using ParameterShapes = std::map<std::string, std::vector<int64_t>>;

inline ParameterShapes read_parameter_shapes(const std::filesystem::path& file) {
  std::ifstream in(file);
  EXPECT_TRUE(in) << file;
  ParameterShapes shapes;
  for (std::string line; std::getline(in, line);) {
    std::istringstream fields(line);
    std::string name;
    fields >> name;
    std::vector<int64_t>& shape = shapes[name];
    for (int64_t dim = 0; fields >> dim;) shape.push_back(dim);
  }
  return shapes;
}

// Parameters and buffers, as a state dict names them.
inline ParameterShapes parameter_shapes(const torch::nn::Module& module) {
  ParameterShapes shapes;
  for (const auto& item : module.named_parameters())
    shapes[item.key()] = item.value().sizes().vec();
  for (const auto& item : module.named_buffers()) shapes[item.key()] = item.value().sizes().vec();
  return shapes;
}

// A state dict of these shapes; only shapes matter to a layout, so no memory is filled.
inline priors::StateDict zero_state_dict(const ParameterShapes& shapes) {
  priors::StateDict weights;
  for (const auto& [name, shape] : shapes) weights[name] = torch::zeros({}).expand(shape);
  return weights;
}

}  // namespace iesrgs::testing
