// libFuzzer harness for the checkpoint reader (zip archive or legacy pickle stream, then the
// unpickler): any byte string must either give a state dict of defined tensors or throw
// iesrgs::Error. A c10::Error escaping, a crash or a huge allocation is a bug.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "core/error.hpp"
#include "priors/state_dict.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  try {
    const iesrgs::priors::StateDict weights = iesrgs::priors::parse_state_dict(
        std::string_view(reinterpret_cast<const char*>(data), size), "fuzz.pth");
    for (const auto& [name, tensor] : weights)
      if (!tensor.defined() || name.empty()) std::abort();
  } catch (const iesrgs::Error&) {
  }
  return 0;
}
