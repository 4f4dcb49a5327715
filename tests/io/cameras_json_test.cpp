#include "io/cameras_json.hpp"

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "io/atomic_file.hpp"
#include "support/temp_dir.hpp"

namespace iesrgs {
namespace {

TEST(CamerasJson, EntriesHoldCentreAndCameraToWorldAs3dgsWritesThem) {
  testing::TempDir dir;
  Camera camera;
  camera.name = "r_7";
  camera.intrinsics = {40, 30, 50, 55, 20, 15};
  camera.rotation = quat_to_rotation(0.5, 0.5, 0.5, 0.5);  // world-to-camera
  camera.translation = {1, -2, 3};
  Camera second = camera;
  second.name = "r_8";
  write_cameras_json(dir / "cameras.json", {camera, second});
  const auto json = nlohmann::json::parse(read_file(dir / "cameras.json"));
  ASSERT_EQ(json.size(), 2u);
  const auto& entry = json[0];
  EXPECT_EQ(entry["id"], 0);
  EXPECT_EQ(json[1]["id"], 1);
  EXPECT_EQ(entry["img_name"], "r_7");
  EXPECT_EQ(entry["width"], 40);
  EXPECT_EQ(entry["height"], 30);
  EXPECT_EQ(entry["fx"], 50.0);
  EXPECT_EQ(entry["fy"], 55.0);
  const Vec3 center = camera.center();
  for (int k = 0; k < 3; ++k) EXPECT_DOUBLE_EQ(entry["position"][k].get<double>(), center[k]);
  // Row r of camera-to-world is column r of world-to-camera.
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c)
      EXPECT_DOUBLE_EQ(entry["rotation"][r][c].get<double>(), camera.rotation(c, r));
}

}  // namespace
}  // namespace iesrgs
