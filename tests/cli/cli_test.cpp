// End-to-end checks of the iesrgs binary: exit codes and one-line errors as a user sees them.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdio>
#include <string>

#include "io/atomic_file.hpp"
#include "support/temp_dir.hpp"

namespace iesrgs {
namespace {

using testing::TempDir;
using testing::write_text;

struct CliRun {
  int status = -1;
  std::string output;  // stdout and stderr together
};

CliRun iesrgs(const std::string& args) {
  CliRun run;
  const std::string command = std::string(IESRGS_CLI_BINARY) + " " + args + " 2>&1";
  FILE* pipe = ::popen(command.c_str(), "r");
  if (!pipe) return run;
  char buffer[4096];
  while (size_t n = std::fread(buffer, 1, sizeof buffer, pipe)) run.output.append(buffer, n);
  const int status = ::pclose(pipe);
  run.status = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return run;
}

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

// The last line of the output: where the CLI puts its one-line error.
std::string last_line(const std::string& output) {
  std::string text = output;
  while (!text.empty() && text.back() == '\n') text.pop_back();
  return text.substr(text.find_last_of('\n') + 1);
}

TEST(Cli, InfoHelpExplainsTheOptions) {
  const CliRun run = iesrgs("info --help");
  EXPECT_EQ(run.status, 0);
  EXPECT_TRUE(contains(run.output, "--load-images")) << run.output;
  EXPECT_TRUE(contains(run.output, "--downscale")) << run.output;
}

TEST(Cli, MissingSceneIsOneLineNamingThePath) {
  TempDir dir;
  const CliRun run = iesrgs("info " + (dir / "nowhere").string());
  EXPECT_EQ(run.status, 1);
  EXPECT_EQ(last_line(run.output),
            "error: " + (dir / "nowhere").string() + ": scene directory not found");
}

TEST(Cli, SynthSceneLoadsAndDecodes) {
  TempDir dir;
  const std::string scene = (dir / "scene").string();
  ASSERT_EQ(iesrgs("synth -o " + scene + " --size 32 --views 3 --test-views 2 --seed 3").status, 0);
  const CliRun info = iesrgs("info " + scene + " --load-images");
  EXPECT_EQ(info.status, 0) << info.output;
  EXPECT_TRUE(contains(info.output, "cameras     5 (3 train, 2 test)")) << info.output;
  EXPECT_TRUE(contains(info.output, "image size  32x32")) << info.output;
  EXPECT_TRUE(contains(info.output, "all 5 decoded")) << info.output;
}

TEST(Cli, LoadImagesStopsAtTheFirstBadImage) {
  TempDir dir;
  const std::string scene = (dir / "scene").string();
  ASSERT_EQ(iesrgs("synth -o " + scene + " --size 32 --views 3 --test-views 1").status, 0);
  const auto bad = dir / "scene" / "train" / "r_1.png";
  write_text(bad, read_file(bad).substr(0, 60));  // truncated
  const CliRun info = iesrgs("info " + scene + " --load-images");
  EXPECT_EQ(info.status, 1);
  EXPECT_TRUE(contains(last_line(info.output), "error: " + bad.string() + ": not a readable"))
      << info.output;
}

TEST(Cli, BadDownscaleIsRejected) {
  const CliRun run = iesrgs("info . --downscale 0");
  EXPECT_NE(run.status, 0);
  EXPECT_TRUE(contains(run.output, "--downscale")) << run.output;
}

}  // namespace
}  // namespace iesrgs
