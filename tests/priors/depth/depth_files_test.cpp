#include "priors/depth/depth_files.hpp"

#include <gtest/gtest.h>

#include "io/image.hpp"
#include "io/npy.hpp"
#include "support/expect_error.hpp"
#include "support/temp_dir.hpp"

namespace iesrgs::priors::depth {
namespace {

using testing::contains;
using testing::error_message;
using testing::TempDir;
using testing::write_text;

TEST(DepthFiles, FolderGivesOneJobPerImageByName) {
  TempDir dir;
  for (const char* name : {"b.JPG", "a.png", "c.jpeg", "notes.txt", "sub/d.png"})
    write_text(dir / "in" / name, "x");
  const std::vector<DepthJob> jobs = plan_depth_jobs(dir / "in", dir / "out");
  ASSERT_EQ(jobs.size(), 3u);
  EXPECT_EQ(jobs[0].image, dir / "in" / "a.png");
  EXPECT_EQ(jobs[0].npy, dir / "out" / "a.npy");
  EXPECT_EQ(jobs[0].preview, dir / "out" / "a_preview.png");
  EXPECT_EQ(jobs[1].npy, dir / "out" / "b.npy");
  EXPECT_EQ(jobs[2].preview, dir / "out" / "c_preview.png");
}

TEST(DepthFiles, SingleImageWritesBesideTheNpy) {
  TempDir dir;
  write_text(dir / "photo.png", "x");
  const std::vector<DepthJob> jobs = plan_depth_jobs(dir / "photo.png", dir / "photo.npy");
  ASSERT_EQ(jobs.size(), 1u);
  EXPECT_EQ(jobs[0].npy, dir / "photo.npy");
  EXPECT_EQ(jobs[0].preview, dir / "photo_preview.png");
  write_text(dir / "out" / "notes.txt", "x");  // an existing folder takes <stem>.npy
  EXPECT_EQ(plan_depth_jobs(dir / "photo.png", dir / "out")[0].npy, dir / "out" / "photo.npy");
}

TEST(DepthFiles, BadPlansNameThePath) {
  TempDir dir;
  write_text(dir / "photo.png", "x");
  write_text(dir / "empty" / "notes.txt", "x");
  write_text(dir / "twins" / "a.png", "x");
  write_text(dir / "twins" / "a.jpg", "x");
  write_text(dir / "clash" / "a.png", "x");
  write_text(dir / "clash" / "a_preview.png", "x");
  EXPECT_EQ(error_message([&] { plan_depth_jobs(dir / "nowhere", dir / "o.npy"); }),
            (dir / "nowhere").string() + ": no such image or folder");
  EXPECT_EQ(error_message([&] { plan_depth_jobs(dir / "photo.png", dir / "photo.png"); }),
            (dir / "photo.png").string() +
                ": depth writes .npy files: name the output .npy, or give an existing folder");
  EXPECT_EQ(error_message([&] { plan_depth_jobs(dir / "empty", dir / "out"); }),
            (dir / "empty").string() + ": no PNG or JPEG images in this folder");
  EXPECT_TRUE(contains(error_message([&] { plan_depth_jobs(dir / "twins", dir / "out"); }),
                       (dir / "out" / "a.npy").string() + ": would be written twice, for " +
                           (dir / "twins" / "a.jpg").string() + " and for " +
                           (dir / "twins" / "a.png").string()));
  EXPECT_TRUE(contains(error_message([&] { plan_depth_jobs(dir / "clash", dir / "clash"); }),
                       (dir / "clash" / "a_preview.png").string() + ": is an input image"));
}

TEST(DepthFiles, OutputsHoldTheRawValuesAndAPreview) {
  TempDir dir;
  const DepthJob job{dir / "in.png", dir / "out" / "d.npy", dir / "out" / "d_preview.png"};
  const torch::Tensor depth = torch::arange(6, torch::kFloat32).view({2, 3}) * 0.5 - 1;
  write_depth_outputs(depth, job);
  const NpyArray npy = read_npy(job.npy);
  EXPECT_EQ(npy.shape, (std::vector<size_t>{2, 3}));
  EXPECT_EQ(npy.data, (std::vector<float>{-1, -0.5, 0, 0.5, 1, 1.5}));
  const Image8 preview = read_image8(job.preview);
  EXPECT_EQ(preview.width, 3);
  EXPECT_EQ(preview.height, 2);
  EXPECT_EQ(preview.channels, 3);
}

}  // namespace
}  // namespace iesrgs::priors::depth
