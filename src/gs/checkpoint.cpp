#include "gs/checkpoint.hpp"

#include <torch/serialize.h>

#include <fstream>
#include <string>

#include "core/byte_reader.hpp"
#include "core/error.hpp"
#include "core/torch_error.hpp"
#include "gs/sh.hpp"
#include "io/atomic_file.hpp"
#include "io/mapped_file.hpp"
#include "io/zip_archive.hpp"

namespace iesrgs::gs {

namespace {

std::string model_key(int p) {
  return std::string("model/") + param_name(Param(p));
}

void save_model(torch::serialize::OutputArchive& archive, const GaussianModel& model) {
  for (int p = 0; p < kParamCount; ++p) archive.write(model_key(p), model.param(Param(p)).detach());
  archive.write("model/active_sh_degree", torch::tensor(int64_t(model.active_sh_degree)));
  if (model.filter_3d.defined()) archive.write("model/filter_3d", model.filter_3d);
}

void check_model(const GaussianModel& model) {
  const int64_t n = model.size();
  const std::vector<int64_t> expected[kParamCount] = {
      {n, 3}, {n, 1, 3}, {n, kShCoefficients - 1, 3}, {n}, {n, 3}, {n, 4}};
  for (int p = 0; p < kParamCount; ++p)
    if (model.param(Param(p)).sizes() != c10::IntArrayRef(expected[p]))
      fail("{} has shape {}", model_key(p), c10::str(model.param(Param(p)).sizes()));
    else if (model.param(Param(p)).scalar_type() != torch::kFloat32)
      fail("{} holds {}, not float32", model_key(p),
           c10::toString(model.param(Param(p)).scalar_type()));
  if (model.filter_3d.defined() && model.filter_3d.sizes() != c10::IntArrayRef{n})
    fail("model/filter_3d has shape {}", c10::str(model.filter_3d.sizes()));
  if (model.active_sh_degree < 0 || model.active_sh_degree > kMaxShDegree)
    fail("active SH degree {} is out of range", model.active_sh_degree);
}

GaussianModel load_model(torch::serialize::InputArchive& archive) {
  GaussianModel model;
  std::array<torch::Tensor, kParamCount> params;
  for (int p = 0; p < kParamCount; ++p) archive.read(model_key(p), params[p]);
  model.set_params(params);
  torch::Tensor degree;
  archive.read("model/active_sh_degree", degree);
  if (degree.numel() != 1) fail("model/active_sh_degree is not a scalar");
  model.active_sh_degree = int(degree.item<int64_t>());
  torch::Tensor filter;
  if (archive.try_read("model/filter_3d", filter)) model.filter_3d = filter.contiguous();
  if (model.means.dim() != 2) fail("model/means is not a matrix");
  check_model(model);
  return model;
}

}  // namespace

void save_training_state(const std::filesystem::path& path, const GaussianModel& model,
                         const GaussianOptimizer& optimizer, const DensifyStats& stats,
                         const CheckpointExtras& extras) {
  torch::serialize::OutputArchive archive;
  save_model(archive, model);
  optimizer.save_state(archive);
  stats.save(archive);
  for (const auto& [name, value] : extras) archive.write("extra/" + name, value);
  // Streamed to the file, not gathered in memory first: a string of the whole checkpoint (twice
  // the model's parameters) set the peak memory of a training. LibTorch ends the process on a
  // short write, so every write is reported whole and the stream's state checked afterwards.
  write_atomically(path, [&](const std::filesystem::path& tmp) {
    std::ofstream out(tmp, std::ios::binary);
    archive.save_to([&out](const void* data, size_t size) {
      out.write(static_cast<const char*>(data), static_cast<std::streamsize>(size));
      return size;
    });
    close_written(out, path);
  });
}

void load_training_state(const std::filesystem::path& path, GaussianModel& model,
                         GaussianOptimizer& optimizer, DensifyStats& stats,
                         CheckpointExtras* extras) {
  // Checked and read through one mapping, so that the bytes loaded are the bytes checked even if
  // the file is replaced meanwhile by a rename, as every writer here replaces files. The pages are
  // dropped once read, as a copy of the whole file beside the tensors loaded from it would set the
  // peak memory of a resume.
  const MappedFile file(path);
  try {
    // LibTorch's reader skips the CRCs, so damaged bytes would load as a different model.
    ZipArchive(file.bytes()).check_all();
    file.drop_pages(0, file.bytes().size());
    torch::serialize::InputArchive archive;
    archive.load_from([&file](uint64_t offset, void* out,
                              size_t size) { return file.read_through(offset, out, size); },
                      [&file] { return file.bytes().size(); },
                      torch::kCPU);  // wherever it was trained
    GaussianModel loaded_model = load_model(archive);
    GaussianOptimizer loaded_optimizer = optimizer;
    loaded_optimizer.load_state(archive, loaded_model);
    DensifyStats loaded_stats;
    loaded_stats.load(archive, loaded_model.size());
    if (extras)
      for (auto& [name, value] : *extras)
        if (!archive.try_read("extra/" + name, value)) value = torch::Tensor();
    model = std::move(loaded_model);
    optimizer = std::move(loaded_optimizer);
    stats = std::move(loaded_stats);
  } catch (const FormatError& e) {
    fail_file(path, std::string("not a readable training checkpoint (") + e.what() + ")");
  } catch (const c10::Error& e) {
    fail_file(path, "not a readable training checkpoint (" + torch_error_line(e) + ")");
  } catch (const Error& e) {
    fail_file(path, e.what());
  }
}

}  // namespace iesrgs::gs
