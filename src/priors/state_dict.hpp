#pragma once
// Reading PyTorch checkpoints (.pth) without Python: both torch.save formats
// (the zip archive and the legacy pickle stream), so official weights load
// by the authors' own parameter names.
#include <torch/torch.h>

#include <filesystem>
#include <map>
#include <string>
#include <string_view>

namespace iesrgs::priors {

// The root of the checkpoint folders: $IESRGS_WEIGHTS_DIR when set, else the development data
// beside the source tree (../shared/data/weights), which may not exist on a user's machine.
std::filesystem::path default_weights_dir();

// Parameter name -> tensor (contiguous, CPU), sorted by name. Floating-point tensors of any
// precision become float32; integer buffers (BatchNorm's num_batches_tracked) keep their type,
// so a strict load into a module that has them still finds them.
using StateDict = std::map<std::string, torch::Tensor>;

// Reads a checkpoint and returns its state dict. Unwraps the usual
// containers ({"params": ...}, {"params_ema": ...}, {"state_dict": ...},
// {"model": ...}; params_ema preferred over params) and strips a leading
// "module." from every name. Throws iesrgs::Error naming the file and the
// problem for anything malformed or unsupported.
StateDict read_state_dict(const std::filesystem::path& file);

// The same for a checkpoint already in memory; `source` names it in error messages.
StateDict parse_state_dict(std::string_view bytes, const std::filesystem::path& source);

// The entry `name`, or null when absent. A present entry must have `dims` dimensions (its shape
// is about to be read), else the error names `file` and the entry.
const torch::Tensor* find_weight(const StateDict& weights, const std::string& name, int64_t dims,
                                 const std::filesystem::path& file);

// Copies `weights` into the parameters and buffers of `module`, strictly:
// every name must exist on both sides with the same shape. The error names
// `file` and the first missing, unexpected or mis-shaped entry.
void load_state_dict(torch::nn::Module& module, const StateDict& weights,
                     const std::filesystem::path& file);

}  // namespace iesrgs::priors
