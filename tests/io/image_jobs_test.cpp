#include "io/image_jobs.hpp"

#include <gtest/gtest.h>

#include "support/expect_error.hpp"
#include "support/temp_dir.hpp"

namespace iesrgs {
namespace {

using testing::error_message;
using testing::TempDir;
using testing::write_text;

TEST(ImageJobs, AnImageGoesToTheNamedFileOrIntoAnExistingFolder) {
  TempDir dir;
  write_text(dir / "a.JPG", "x");
  write_text(dir / "out" / "notes.txt", "x");
  const std::vector<ImageJob> named = plan_image_jobs(dir / "a.JPG", dir / "b.PNG", ".png", "x");
  ASSERT_EQ(named.size(), 1u);
  EXPECT_EQ(named[0].outputs, std::vector<std::filesystem::path>{dir / "b.PNG"});
  EXPECT_EQ(plan_image_jobs(dir / "a.JPG", dir / "out", ".png", "x")[0].outputs[0],
            dir / "out" / "a.png");
  EXPECT_EQ(
      error_message([&] { plan_image_jobs(dir / "a.JPG", dir / "b.jpg", ".png", "upscale"); }),
      (dir / "b.jpg").string() +
          ": upscale writes .png files: name the output .png, or give an existing folder");
}

TEST(ImageJobs, AFolderCannotGoToAFile) {
  TempDir dir;
  write_text(dir / "in" / "a.png", "x");
  write_text(dir / "file.png", "x");
  EXPECT_EQ(error_message([&] { plan_image_jobs(dir / "in", dir / "file.png", ".png", "x"); }),
            (dir / "file.png").string() + ": is a file, but the input is a folder");
}

TEST(ImageJobs, ResultsNeverOverwriteAnInputNorEachOther) {
  TempDir dir;
  write_text(dir / "in" / "a.png", "x");
  write_text(dir / "in" / "b.png", "x");
  const std::vector<ImageJob> into_input = plan_image_jobs(dir / "in", dir / "in", ".png", "x");
  EXPECT_EQ(error_message([&] { refuse_overwrites(into_input); }),
            (dir / "in" / "a.png").string() + ": is an input image; write the results elsewhere");
  // Through another spelling of the same folder, too.
  std::vector<ImageJob> jobs = plan_image_jobs(dir / "in", dir / "out", ".png", "x");
  refuse_overwrites(jobs);
  jobs[1].outputs.push_back(dir / "out" / ".." / "out" / "a.png");
  EXPECT_EQ(error_message([&] { refuse_overwrites(jobs); }),
            (dir / "out" / ".." / "out" / "a.png").string() + ": would be written twice, for " +
                (dir / "in" / "a.png").string() + " and for " + (dir / "in" / "b.png").string() +
                "; rename one");
}

// A folder of images fills a folder of results, which is held while they are written; a single
// image's result is not.
TEST(ImageJobs, AFolderOfResultsIsHeldWhileTheJobsRun) {
  TempDir dir;
  std::filesystem::create_directories(dir / "in");
  write_text(dir / "in" / "a.png", "x");
  {
    const auto lock = lock_results_folder(dir / "in", dir / "out");
    ASSERT_NE(lock, nullptr);
    EXPECT_NE(
        error_message([&] { FolderLock again(dir / "out"); }).find("in use by another process"),
        std::string::npos);
  }
  EXPECT_EQ(lock_results_folder(dir / "in" / "a.png", dir / "out.png"), nullptr);
  EXPECT_FALSE(std::filesystem::exists(dir / "out.png"));
}

}  // namespace
}  // namespace iesrgs
