#include "priors/state_dict.hpp"

#include <fmt/format.h>
#include <fmt/ostream.h>

#include <cstdlib>
#include <cstring>
#include <string_view>

#include "core/byte_reader.hpp"
#include "core/error.hpp"
#include "core/paths.hpp"
#include "io/atomic_file.hpp"
#include "io/zip_archive.hpp"
#include "priors/pickle.hpp"

namespace iesrgs::priors {

std::filesystem::path default_weights_dir() {
  return env_path("IESRGS_WEIGHTS_DIR").value_or(IESRGS_DEV_WEIGHTS_DIR);
}

namespace {

namespace fs = std::filesystem;
using pickle::Kind;
using pickle::Object;

// The 80-bit magic number that opens the legacy format, as pickle's little-endian bytes.
const std::string_view kLegacyMagic("\x6c\xfc\x9c\x46\xf9\x20\x6a\xa8\x50\x19", 10);
constexpr int64_t kLegacyProtocol = 1001;
// Containers that training code wraps around the weights, most preferred first.
const char* const kWrapperKeys[] = {"params_ema", "params", "state_dict", "model"};
constexpr int kMaxWrapperDepth = 8;

// A decoded checkpoint: the pickled object graph and the storages its tensors view.
struct Checkpoint {
  pickle::Unpickler unpickler;
  size_t root = 0;
  std::map<std::string, torch::Tensor> storages;  // key -> 1-D tensor of its elements
};

torch::Tensor storage_from_bytes(std::string_view bytes, torch::ScalarType dtype) {
  const size_t element_size = c10::elementSize(dtype);
  if (bytes.size() % element_size) throw FormatError("storage size is not a whole element count");
  torch::Tensor storage =
      torch::empty({static_cast<int64_t>(bytes.size() / element_size)}, torch::dtype(dtype));
  if (!bytes.empty()) std::memcpy(storage.data_ptr(), bytes.data(), bytes.size());
  return storage;
}

bool is_zip(std::string_view bytes) {
  return bytes.substr(0, 4) == "PK\x03\x04";
}

// torch.save's archive keeps everything under one folder named after the file it first had.
std::string archive_folder(const ZipArchive& zip) {
  for (const std::string& name : zip.names()) {
    const size_t slash = name.find('/');
    if (slash != std::string::npos && name.compare(slash, std::string::npos, "/data.pkl") == 0)
      return name.substr(0, slash + 1);
  }
  throw FormatError("zip archive without data.pkl (not a torch.save checkpoint)");
}

void load_zip(std::string_view bytes, Checkpoint& checkpoint) {
  const ZipArchive zip(bytes);
  const std::string folder = archive_folder(zip);
  if (zip.contains(folder + "byteorder") && zip.read(folder + "byteorder") != "little")
    throw FormatError("big-endian checkpoints are not supported");
  const std::string data = zip.read(folder + "data.pkl");
  ByteReader reader(data);
  checkpoint.root = checkpoint.unpickler.run(reader);
  for (const auto& [key, dtype] : checkpoint.unpickler.storages())
    checkpoint.storages[key] = storage_from_bytes(zip.read(folder + "data/" + key), dtype);
}

void expect_legacy_magic(ByteReader& reader, pickle::Unpickler& unpickler) {
  const char* const problem = "not a PyTorch checkpoint (neither zip nor legacy torch.save)";
  try {
    const Object& magic = unpickler.object(unpickler.run(reader));
    if (magic.kind == Kind::LargeInt && magic.text == kLegacyMagic) return;
  } catch (const FormatError&) {
  }
  throw FormatError(problem);
}

void expect_legacy_header(ByteReader& reader, pickle::Unpickler& unpickler) {
  const Object& protocol = unpickler.object(unpickler.run(reader));
  if (protocol.kind != Kind::Int || protocol.integer != kLegacyProtocol)
    throw FormatError("unsupported legacy torch.save protocol version");
  const Object& system = unpickler.object(unpickler.run(reader));
  const auto little_endian =
      system.kind == Kind::Dict ? unpickler.find(system, "little_endian") : std::nullopt;
  if (!little_endian || unpickler.object(*little_endian).integer != 1)
    throw FormatError("big-endian checkpoints are not supported");
}

// After the pickles: the storage keys in file order, then per storage an int64 element count
// and the raw elements.
void read_legacy_storages(ByteReader& reader, Checkpoint& checkpoint) {
  const pickle::Unpickler& unpickler = checkpoint.unpickler;
  const Object& keys = unpickler.object(checkpoint.unpickler.run(reader));
  if (keys.kind != Kind::List) throw FormatError("legacy storage key list missing");
  for (size_t id : keys.items) {
    const std::string& key = unpickler.object(id).text;
    const auto dtype = unpickler.storages().find(key);
    if (dtype == unpickler.storages().end())
      throw FormatError(fmt::format("legacy storage '{}' is used by no tensor", key));
    const auto count = reader.little<int64_t>();
    const size_t element_size = c10::elementSize(dtype->second);
    if (count < 0 || uint64_t(count) > reader.remaining() / element_size)
      throw FormatError(fmt::format("truncated storage '{}'", key));
    checkpoint.storages[key] = storage_from_bytes(reader.take(count * element_size), dtype->second);
  }
}

void load_legacy(std::string_view bytes, Checkpoint& checkpoint) {
  ByteReader reader(bytes);
  expect_legacy_magic(reader, checkpoint.unpickler);
  expect_legacy_header(reader, checkpoint.unpickler);
  checkpoint.root = checkpoint.unpickler.run(reader);
  read_legacy_storages(reader, checkpoint);
}

const Object& unwrap_containers(const pickle::Unpickler& unpickler, size_t root) {
  const Object* dict = &unpickler.object(root);
  for (int depth = 0; depth < kMaxWrapperDepth; ++depth) {
    if (dict->kind != Kind::Dict)
      throw FormatError(fmt::format(
          "holds a pickled {} where a network's weights are a dict of tensors (an iesrgs "
          "training checkpoint, say, is no network checkpoint)",
          kind_name(dict->kind)));
    const Object* inner = nullptr;
    for (const char* key : kWrapperKeys) {
      const auto found = unpickler.find(*dict, key);
      if (found && unpickler.object(*found).kind == Kind::Dict) {
        inner = &unpickler.object(*found);
        break;
      }
    }
    if (!inner) return *dict;
    dict = inner;
  }
  throw FormatError("weight containers nested too deeply");
}

// Checks that the view stays inside its storage before handing it to as_strided, and that it
// does not expand the storage (a corrupt size could otherwise request any amount of memory).
void check_view(const pickle::TensorView& view, int64_t available) {
  int64_t count = 1;
  for (size_t d = 0; d < view.sizes.size(); ++d) {
    if (view.sizes[d] < 0 || view.strides[d] < 0) throw FormatError("negative size or stride");
    if (view.sizes[d] == 0) return;
    if (count > available / view.sizes[d]) throw FormatError("more elements than its storage");
    count *= view.sizes[d];
  }
  if (view.offset < 0 || view.offset >= available) throw FormatError("offset outside its storage");
  int64_t last = view.offset;
  for (size_t d = 0; d < view.sizes.size(); ++d) {
    if (view.strides[d] == 0) continue;
    if (view.sizes[d] - 1 > (available - 1 - last) / view.strides[d])
      throw FormatError("extends past its storage");
    last += (view.sizes[d] - 1) * view.strides[d];
  }
}

torch::Tensor materialize(const pickle::TensorView& view, const torch::Tensor& storage) {
  check_view(view, storage.numel());
  const bool floating = torch::isFloatingType(storage.scalar_type());
  const torch::ScalarType dtype = floating ? torch::kFloat : storage.scalar_type();
  const auto elements = c10::multiply_integers(view.sizes);
  if (elements == 0) return torch::empty(view.sizes, torch::dtype(dtype));
  return storage.as_strided(view.sizes, view.strides, view.offset)
      .to(dtype, /*non_blocking=*/false, /*copy=*/true, torch::MemoryFormat::Contiguous);
}

std::string strip_module_prefix(const std::string& name) {
  const std::string_view prefix = "module.";
  return name.compare(0, prefix.size(), prefix) == 0 ? name.substr(prefix.size()) : name;
}

StateDict to_state_dict(const Checkpoint& checkpoint) {
  const pickle::Unpickler& unpickler = checkpoint.unpickler;
  const Object& dict = unwrap_containers(unpickler, checkpoint.root);
  StateDict weights;
  for (size_t i = 0; i + 1 < dict.items.size(); i += 2) {
    const Object& key = unpickler.object(dict.items[i]);
    const Object& value = unpickler.object(dict.items[i + 1]);
    if (key.kind != Kind::String) throw FormatError("state dict key is not a string");
    if (value.kind != Kind::Tensor)
      throw FormatError(
          fmt::format("entry '{}' is a {}, not a tensor", key.text,
                      value.kind == Kind::Opaque ? value.text : kind_name(value.kind)));
    try {
      const std::string name = strip_module_prefix(key.text);
      const auto storage = checkpoint.storages.find(value.tensor.storage);
      if (storage == checkpoint.storages.end()) throw FormatError("storage data missing");
      const torch::Tensor tensor = materialize(value.tensor, storage->second);
      if (!weights.emplace(name, tensor).second) throw FormatError("name appears twice");
    } catch (const FormatError& e) {
      throw FormatError(fmt::format("tensor '{}': {}", key.text, e.what()));
    }
  }
  if (weights.empty()) throw FormatError("holds no tensors");
  return weights;
}

}  // namespace

StateDict read_state_dict(const fs::path& file) {
  return parse_state_dict(read_file(file), file);
}

StateDict parse_state_dict(std::string_view bytes, const fs::path& source) {
  try {
    Checkpoint checkpoint;
    if (is_zip(bytes)) {
      load_zip(bytes, checkpoint);
    } else {
      load_legacy(bytes, checkpoint);
    }
    return to_state_dict(checkpoint);
  } catch (const FormatError& e) {
    fail_file(source, e.what());
  }
}

const torch::Tensor* find_weight(const StateDict& weights, const std::string& name, int64_t dims,
                                 const fs::path& file) {
  const auto it = weights.find(name);
  if (it == weights.end()) return nullptr;
  if (it->second.dim() != dims)
    fail_file(file, fmt::format("{} has {} dimensions, not {}", name, it->second.dim(), dims));
  return &it->second;
}

void load_state_dict(torch::nn::Module& module, const StateDict& weights, const fs::path& file) {
  std::map<std::string, torch::Tensor> targets;
  for (const auto& item : module.named_parameters()) targets.emplace(item.key(), item.value());
  for (const auto& item : module.named_buffers()) targets.emplace(item.key(), item.value());
  for (const auto& [name, target] : targets)
    if (!weights.count(name))
      fail_file(file, fmt::format("missing '{}' {}", name, fmt::streamed(target.sizes())));
  for (const auto& [name, source] : weights)
    if (!targets.count(name)) fail_file(file, fmt::format("unexpected '{}'", name));
  for (const auto& [name, target] : targets) {
    const torch::Tensor& source = weights.at(name);
    if (source.sizes() != target.sizes())
      fail_file(file, fmt::format("'{}' has shape {} in the file but {} in the model", name,
                                  fmt::streamed(source.sizes()), fmt::streamed(target.sizes())));
    // Damage a CRC cannot see (a file saved after training diverged) would blacken every output.
    if (source.is_floating_point() && !torch::isfinite(source).all().item<bool>())
      fail_file(file, fmt::format("'{}' holds non-finite values (NaN or infinity)", name));
  }
  const torch::NoGradGuard no_grad;
  for (auto& [name, target] : targets) target.copy_(weights.at(name));
}

}  // namespace iesrgs::priors
