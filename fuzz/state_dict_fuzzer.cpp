// libFuzzer harness for the checkpoint reader (zip archive or legacy pickle stream, then the
// unpickler): any byte string must either give a state dict of defined tensors or throw
// iesrgs::Error. A c10::Error escaping, a crash or a huge allocation is a bug. The same bytes also
// go through the CRC check that training checkpoints pass before LibTorch reads them, which may
// only throw FormatError.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "core/byte_reader.hpp"
#include "core/error.hpp"
#include "io/zip_archive.hpp"
#include "priors/state_dict.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string_view bytes(reinterpret_cast<const char*>(data), size);
  try {
    iesrgs::ZipArchive(bytes).check_all();
  } catch (const iesrgs::FormatError&) {
  }
  try {
    const iesrgs::priors::StateDict weights = iesrgs::priors::parse_state_dict(bytes, "fuzz.pth");
    for (const auto& [name, tensor] : weights)
      if (!tensor.defined() || name.empty()) std::abort();
  } catch (const iesrgs::Error&) {
  }
  return 0;
}
