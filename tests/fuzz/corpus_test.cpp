// The fuzz harnesses (fuzz/*_fuzzer.cpp) on their seeds, as scripts/fuzz.sh seeds them: so that
// they keep compiling between fuzzing sessions, and every seed keeps passing their checks (a
// harness aborts on a broken invariant). tests/CMakeLists.txt renames each entry point to
// fuzz_<name>.
#include <gtest/gtest.h>

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "io/atomic_file.hpp"

#define IESRGS_HARNESS(name) extern "C" int fuzz_##name(const uint8_t* data, size_t size);
IESRGS_HARNESS(colmap)
IESRGS_HARNESS(image)
IESRGS_HARNESS(json)
IESRGS_HARNESS(npy)
IESRGS_HARNESS(ply)
IESRGS_HARNESS(splat)
IESRGS_HARNESS(spz)
IESRGS_HARNESS(state_dict)
#undef IESRGS_HARNESS

namespace iesrgs {
namespace {

namespace fs = std::filesystem;

struct Harness {
  const char* name;
  int (*run)(const uint8_t*, size_t);
};

// fuzz/corpus/<name>_fuzzer/, tests/data/<name>/ and tests/data/*/<name>/, as scripts/fuzz.sh.
std::vector<fs::path> seed_files(const std::string& name) {
  const fs::path root = fs::path(IESRGS_TEST_DATA).parent_path().parent_path();
  std::vector<fs::path> folders = {root / "fuzz" / "corpus" / (name + "_fuzzer"),
                                   root / "tests" / "data" / name};
  for (const fs::directory_entry& entry : fs::directory_iterator(root / "tests" / "data"))
    if (entry.is_directory()) folders.push_back(entry.path() / name);
  std::vector<fs::path> files;
  for (const fs::path& folder : folders) {
    if (!fs::is_directory(folder)) continue;
    for (const fs::directory_entry& entry : fs::recursive_directory_iterator(folder))
      if (entry.is_regular_file()) files.push_back(entry.path());
  }
  return files;
}

TEST(FuzzCorpus, EveryHarnessPassesItsSeedsAndEdgeInputs) {
  const Harness harnesses[] = {{"colmap", fuzz_colmap}, {"image", fuzz_image},
                               {"json", fuzz_json},     {"npy", fuzz_npy},
                               {"ply", fuzz_ply},       {"splat", fuzz_splat},
                               {"spz", fuzz_spz},       {"state_dict", fuzz_state_dict}};
  size_t seeds = 0;
  for (const Harness& harness : harnesses) {
    SCOPED_TRACE(harness.name);
    // An empty input and a byte of each kind: what every fuzzing session tries first.
    for (const std::string& input :
         {std::string(), std::string(1, '\0'), std::string("{"), std::string(64, '\xff')})
      EXPECT_EQ(harness.run(reinterpret_cast<const uint8_t*>(input.data()), input.size()), 0);
    for (const fs::path& file : seed_files(harness.name)) {
      SCOPED_TRACE(file.string());
      const std::string bytes = read_file(file);
      EXPECT_EQ(harness.run(reinterpret_cast<const uint8_t*>(bytes.data()), bytes.size()), 0);
      ++seeds;
    }
  }
  EXPECT_GT(seeds, 20u);  // the seed folders are where scripts/fuzz.sh looks
}

}  // namespace
}  // namespace iesrgs
