#pragma once
// Everything training needs to resume exactly where it stopped: the model, the Adam moments
// and step count, and the densification accumulators, in one torch archive.
#include <filesystem>
#include <map>
#include <string>

#include "gs/densify.hpp"
#include "gs/model.hpp"
#include "gs/optimizer.hpp"

namespace iesrgs::gs {

// What the caller keeps beside the model to resume exactly (iteration, random states, ...).
using CheckpointExtras = std::map<std::string, torch::Tensor>;

// Written atomically.
void save_training_state(const std::filesystem::path& path, const GaussianModel& model,
                         const GaussianOptimizer& optimizer, const DensifyStats& stats,
                         const CheckpointExtras& extras = {});

// Replaces all three with the stored state, bit for bit; the optimizer keeps its learning-rate
// settings. Throws Error naming the file when it is unreadable or inconsistent.
// `extras` gets every extra stored under the names it already holds; a missing one is left
// undefined.
void load_training_state(const std::filesystem::path& path, GaussianModel& model,
                         GaussianOptimizer& optimizer, DensifyStats& stats,
                         CheckpointExtras* extras = nullptr);

}  // namespace iesrgs::gs
