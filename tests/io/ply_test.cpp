#include "io/ply.hpp"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include "io/atomic_file.hpp"
#include "support/captured_log.hpp"
#include "support/expect_error.hpp"
#include "support/temp_dir.hpp"

namespace iesrgs {
namespace {

namespace fs = std::filesystem;
using testing::error_message;
using testing::TempDir;
using testing::write_text;

// Distinct values per array and element, so that any mix-up of properties shows.
std::vector<float> ramp(size_t size, float start) {
  std::vector<float> values(size);
  for (size_t i = 0; i < size; ++i) values[i] = start + 0.25f * float(i);
  return values;
}

SplatCloud make_cloud(int sh_degree, size_t count, bool with_filter) {
  const size_t rest = size_t((sh_degree + 1) * (sh_degree + 1) - 1);
  SplatCloud cloud;
  cloud.sh_degree = sh_degree;
  cloud.positions = ramp(3 * count, -1.f);
  cloud.sh_dc = ramp(3 * count, 100.f);
  cloud.sh_rest = ramp(3 * rest * count, 200.f);
  cloud.opacity = ramp(count, -2.f);
  cloud.log_scales = ramp(3 * count, -5.f);
  cloud.rotations = ramp(4 * count, 0.5f);
  if (with_filter) cloud.filter_3d = ramp(count, 0.01f);
  return cloud;
}

void expect_same(const SplatCloud& a, const SplatCloud& b) {
  EXPECT_EQ(a.sh_degree, b.sh_degree);
  EXPECT_EQ(a.positions, b.positions);
  EXPECT_EQ(a.sh_dc, b.sh_dc);
  EXPECT_EQ(a.sh_rest, b.sh_rest);
  EXPECT_EQ(a.opacity, b.opacity);
  EXPECT_EQ(a.log_scales, b.log_scales);
  EXPECT_EQ(a.rotations, b.rotations);
  EXPECT_EQ(a.filter_3d, b.filter_3d);
}

std::string header_of(const std::string& bytes) {
  const std::string end = "end_header\n";
  return bytes.substr(0, bytes.find(end) + end.size());
}

float float_at(const std::string& bytes, size_t header_size, size_t index) {
  float value;
  std::memcpy(&value, bytes.data() + header_size + index * sizeof(float), sizeof(float));
  return value;
}

TEST(Ply, RoundTripsEveryShDegreeWithAndWithoutFilter) {
  TempDir dir;
  for (int degree = 0; degree <= 3; ++degree)
    for (bool with_filter : {false, true}) {
      SCOPED_TRACE(::testing::Message() << "degree " << degree << " filter " << with_filter);
      const SplatCloud cloud = make_cloud(degree, 5, with_filter);
      write_ply(dir / "scene.ply", cloud);
      const SplatCloud back = read_ply(dir / "scene.ply");
      expect_same(back, cloud);
      EXPECT_EQ(back.has_filter_3d(), with_filter);
      // Only Mip-Splatting writes filter_3D; any other .ply is drawn as 3DGS draws it.
      EXPECT_EQ(back.antialiased, with_filter);
    }
}

TEST(Ply, EmptyCloudRoundTrips) {
  TempDir dir;
  write_ply(dir / "empty.ply", make_cloud(2, 0, false));
  const SplatCloud back = read_ply(dir / "empty.ply");
  EXPECT_EQ(back.size(), 0u);
  EXPECT_EQ(back.sh_degree, 2);
}

TEST(Ply, HeaderAndSizeMatchThe3dgsLayout) {
  TempDir dir;
  write_ply(dir / "d1.ply", make_cloud(1, 2, true));
  const std::string bytes = read_file(dir / "d1.ply");
  const std::string expected_header =
      "ply\nformat binary_little_endian 1.0\nelement vertex 2\n"
      "property float x\nproperty float y\nproperty float z\n"
      "property float nx\nproperty float ny\nproperty float nz\n"
      "property float f_dc_0\nproperty float f_dc_1\nproperty float f_dc_2\n"
      "property float f_rest_0\nproperty float f_rest_1\nproperty float f_rest_2\n"
      "property float f_rest_3\nproperty float f_rest_4\nproperty float f_rest_5\n"
      "property float f_rest_6\nproperty float f_rest_7\nproperty float f_rest_8\n"
      "property float opacity\n"
      "property float scale_0\nproperty float scale_1\nproperty float scale_2\n"
      "property float rot_0\nproperty float rot_1\nproperty float rot_2\nproperty float rot_3\n"
      "property float filter_3D\nend_header\n";
  EXPECT_EQ(header_of(bytes), expected_header);
  EXPECT_EQ(bytes.size(), expected_header.size() + 2 * 27 * sizeof(float));

  // Degree 3 without filter: the 62 properties of a 3DGS point_cloud.ply.
  write_ply(dir / "d3.ply", make_cloud(3, 3, false));
  const std::string d3 = read_file(dir / "d3.ply");
  const std::string d3_header = header_of(d3);
  size_t properties = 0;
  for (size_t pos = 0; (pos = d3_header.find("property float ", pos)) != std::string::npos; ++pos)
    ++properties;
  EXPECT_EQ(properties, 62u);
  EXPECT_NE(d3_header.find("f_rest_44\nproperty float opacity\n"), std::string::npos);
  EXPECT_NE(d3_header.find("rot_3\nend_header\n"), std::string::npos);
  EXPECT_EQ(d3.size(), d3_header.size() + 3 * 62 * sizeof(float));
}

TEST(Ply, RestCoefficientsAreChannelMajorAndNormalsZero) {
  TempDir dir;
  SplatCloud cloud = make_cloud(1, 1, false);
  // Stored (K-1, 3): coefficient k of channel c is 10 c + k.
  for (int k = 0; k < 3; ++k)
    for (int c = 0; c < 3; ++c) cloud.sh_rest[3 * k + c] = float(10 * c + k);
  write_ply(dir / "rest.ply", cloud);
  const std::string bytes = read_file(dir / "rest.ply");
  const size_t header_size = header_of(bytes).size();
  for (size_t normal = 3; normal < 6; ++normal)
    EXPECT_EQ(float_at(bytes, header_size, normal), 0.f);
  const float expected[9] = {0, 1, 2, 10, 11, 12, 20, 21, 22};
  for (size_t j = 0; j < 9; ++j)
    EXPECT_EQ(float_at(bytes, header_size, 9 + j), expected[j]) << "f_rest_" << j;
}

double sigmoid(double x) {
  return 1 / (1 + std::exp(-x));
}

TEST(Ply, BakedFilterWidensScalesAndLowersOpacity) {
  TempDir dir;
  SplatCloud cloud = make_cloud(1, 3, true);
  cloud.log_scales = {-4.f, -3.f, -2.5f, -1.f, -1.f, -1.f, -6.f, -2.f, -3.f};
  cloud.opacity = {0.5f, -1.f, 30.f};
  cloud.filter_3d = {0.02f, 0.f, 0.01f};
  write_ply_filter_baked(dir / "baked.ply", cloud);
  EXPECT_EQ(read_file(dir / "baked.ply").find("filter_3D"), std::string::npos);
  const SplatCloud baked = read_ply(dir / "baked.ply");
  EXPECT_FALSE(baked.has_filter_3d());
  for (size_t i = 0; i < 3; ++i) {
    const double f2 = double(cloud.filter_3d[i]) * cloud.filter_3d[i];
    double det_ratio = 1;
    for (size_t k = 0; k < 3; ++k) {
      const double s2 = std::exp(2.0 * cloud.log_scales[3 * i + k]);
      det_ratio *= s2 / (s2 + f2);
      EXPECT_NEAR(baked.log_scales[3 * i + k], std::log(std::sqrt(s2 + f2)), 1e-5);
    }
    const double p = sigmoid(cloud.opacity[i]) * std::sqrt(det_ratio);
    EXPECT_NEAR(baked.opacity[i], std::log(p / (1 - p)), 1e-4) << "Gaussian " << i;
  }
  // A zero filter changes nothing.
  for (size_t k = 3; k < 6; ++k) EXPECT_EQ(baked.log_scales[k], cloud.log_scales[k]);
  EXPECT_EQ(baked.opacity[1], cloud.opacity[1]);
  EXPECT_EQ(baked.positions, cloud.positions);
  EXPECT_EQ(baked.sh_rest, cloud.sh_rest);
  EXPECT_EQ(baked.rotations, cloud.rotations);
}

TEST(Ply, BakingKeepsSaturatedOpacityFinite) {
  TempDir dir;
  SplatCloud cloud = make_cloud(0, 1, true);
  cloud.opacity = {800.f};
  cloud.filter_3d = {0.f};
  write_ply_filter_baked(dir / "saturated.ply", cloud);
  EXPECT_EQ(read_ply(dir / "saturated.ply").opacity[0], 800.f);
}

TEST(Ply, ReadsHandWrittenAsciiInAnyOrderAndType) {
  TempDir dir;
  // CRLF line ends, shuffled order, doubles and integers, an unknown property, no normals, a
  // face element after the vertices, a number with a leading '+'.
  write_text(dir / "hand.ply",
             "ply\r\nformat ascii 1.0\r\ncomment written by hand\r\nelement vertex 2\r\n"
             "property double opacity\r\nproperty float rot_0\r\nproperty float rot_1\r\n"
             "property float rot_2\r\nproperty float rot_3\r\nproperty uchar red\r\n"
             "property float scale_2\r\nproperty float scale_1\r\nproperty float scale_0\r\n"
             "property float f_dc_0\r\nproperty float f_dc_1\r\nproperty float f_dc_2\r\n"
             "property int x\r\nproperty float y\r\nproperty float z\r\n"
             "element face 1\r\nproperty list uchar int vertex_indices\r\nend_header\r\n"
             "-0.5 1 0 0 0 255 -3 -2 -1 0.1 0.2 0.3 7 8.5 9\r\n"
             "+2.5e1 0.7071 0.7071 0 0 0 -6 -5 -4 1 2 3 -1 -2 -3\r\n"
             "3 0 1 1\r\n");
  const SplatCloud cloud = read_ply(dir / "hand.ply");
  EXPECT_EQ(cloud.sh_degree, 0);
  EXPECT_FALSE(cloud.has_filter_3d());
  EXPECT_EQ(cloud.positions, (std::vector<float>{7, 8.5f, 9, -1, -2, -3}));
  EXPECT_EQ(cloud.opacity, (std::vector<float>{-0.5f, 25}));
  EXPECT_EQ(cloud.log_scales, (std::vector<float>{-1, -2, -3, -4, -5, -6}));
  EXPECT_EQ(cloud.sh_dc, (std::vector<float>{0.1f, 0.2f, 0.3f, 1, 2, 3}));
  EXPECT_EQ(cloud.rotations, (std::vector<float>{1, 0, 0, 0, 0.7071f, 0.7071f, 0, 0}));
  EXPECT_TRUE(cloud.sh_rest.empty());
}

TEST(Ply, PointCloudsAsOpen3dAndColmapWriteThem) {
  // Binary, double positions, float colours in [0, 1], normals and an alpha among them.
  std::string bytes =
      "ply\nformat binary_little_endian 1.0\nelement vertex 2\nproperty double x\n"
      "property double y\nproperty double z\nproperty float nx\nproperty float red\n"
      "property float green\nproperty float blue\nproperty uchar alpha\nend_header\n";
  const auto put = [&bytes](auto value) {
    bytes.append(reinterpret_cast<const char*>(&value), sizeof(value));
  };
  for (const double position : {1.5, -2.0, 1e-3}) put(position);
  for (const float value : {0.0f, 1.0f, 0.5f, 2.0f}) put(value);  // nx, colours (2 clamps)
  put(uint8_t(7));
  for (const double position : {4.0, 5.0, 6.0}) put(position);
  for (const float value : {0.0f, 0.0f, -1.0f, std::nanf("")}) put(value);
  put(uint8_t(7));
  const PointCloud points = parse_point_ply(bytes, "points.ply");
  ASSERT_EQ(points.positions.size(), 2u);
  EXPECT_EQ(points.positions[0].x, 1.5);
  EXPECT_EQ(points.positions[0].z, 1e-3);
  EXPECT_EQ(points.positions[1].y, 5.0);
  EXPECT_EQ(points.colors[0], (std::array<uint8_t, 3>{255, 128, 255}));
  EXPECT_EQ(points.colors[1], (std::array<uint8_t, 3>{0, 0, 0}));

  // Points without colours are grey; without a position, no points.
  const std::string bare =
      "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\n"
      "property float y\nproperty float z\nproperty float nx\n"
      "end_header\n1 2 3 0.5\n";
  EXPECT_EQ(parse_point_ply(bare, "bare.ply").colors[0], (std::array<uint8_t, 3>{128, 128, 128}));
  const std::string flat =
      "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\n"
      "property float y\nproperty uchar red\nend_header\n1 2 3\n";
  const std::string message = error_message([&] { parse_point_ply(flat, "flat.ply"); });
  EXPECT_NE(message.find("flat.ply: missing property 'z' (a point cloud has x y z"),
            std::string::npos)
      << message;
  const std::string infinite =
      "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\n"
      "property float y\nproperty double z\nproperty uchar red\n"
      "property uchar green\nproperty uchar blue\nend_header\n"
      "1 2 1e300 0 0 0\n";
  EXPECT_NE(error_message([&] {
              parse_point_ply(infinite, "far.ply");
            }).find("far.ply: every point is left out: vertex 0: property 'z' is not a finite"),
            std::string::npos);
  EXPECT_NE(error_message([&] {
              parse_point_ply(infinite.substr(0, infinite.size() - 4), "cut");
            }).find("cut: truncated"),
            std::string::npos);
}

// A valid binary file with `from` replaced by `to` (which must occur in it).
std::string patched(const std::string& bytes, const std::string& from, const std::string& to) {
  std::string result = bytes;
  const size_t at = result.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  return at == std::string::npos ? result : result.replace(at, from.size(), to);
}

TEST(Ply, TheTrainingBackgroundRoundTripsAsAComment) {
  TempDir dir;
  SplatCloud cloud = make_cloud(0, 2, true);
  EXPECT_FALSE(cloud.background.has_value());
  write_ply(dir / "plain.ply", cloud);
  EXPECT_FALSE(read_ply(dir / "plain.ply").background.has_value());

  cloud.background = std::array<float, 3>{0.1f, 0.5f, 1};
  write_ply(dir / "gray.ply", cloud);
  const std::string bytes = read_file(dir / "gray.ply");
  EXPECT_NE(header_of(bytes).find("\ncomment background 0.1 0.5 1\nelement vertex 2\n"),
            std::string::npos);
  EXPECT_EQ(read_ply(dir / "gray.ply").background, cloud.background);
  write_ply_filter_baked(dir / "baked.ply", cloud);
  EXPECT_EQ(read_ply(dir / "baked.ply").background, cloud.background);

  // Comments are for people: one that is not a background in [0, 1] is skipped, not refused.
  for (const char* comment :
       {"background 0.1 0.5", "background 0.1 0.5 2", "background a b c", "made by hand"}) {
    SCOPED_TRACE(comment);
    write_text(dir / "odd.ply", patched(bytes, "background 0.1 0.5 1", comment));
    const SplatCloud odd = read_ply(dir / "odd.ply");
    EXPECT_FALSE(odd.background.has_value());
    expect_same(odd, cloud);
  }
}

// Ascii files with one vertex element of `count` Gaussians (degree 0) and the given data lines.
std::string ascii_ply(const std::string& count, const std::string& data) {
  return "ply\nformat ascii 1.0\nelement vertex " + count +
         "\nproperty float x\nproperty float y\nproperty float z\nproperty float f_dc_0\n"
         "property float f_dc_1\nproperty float f_dc_2\nproperty float opacity\n"
         "property float scale_0\nproperty float scale_1\nproperty float scale_2\n"
         "property float rot_0\nproperty float rot_1\nproperty float rot_2\nproperty float rot_3\n"
         "end_header\n" +
         data;
}

TEST(Ply, RejectsBadInputNamingFileAndProblem) {
  TempDir dir;
  write_ply(dir / "good.ply", make_cloud(1, 4, true));
  const std::string good = read_file(dir / "good.ply");
  const size_t header_size = header_of(good).size();
  const std::string row = "0.25 0.25 0.25 0.25 0.25 0.25 0.25 0.25 0.25 0.25 1.00 0.25 0.25 0.25\n";
  const struct {
    std::string file, bytes, problem;
  } cases[] = {
      {"magic.ply", "PLY\n" + good.substr(4), "not a PLY file"},
      {"header.ply", good.substr(0, header_size / 2), "truncated header"},
      {"body.ply", good.substr(0, good.size() - 3), "4 vertices do not fit"},
      {"count.ply", patched(good, "vertex 4", "vertex 400000000000"), "do not fit"},
      {"huge.ply", patched(good, "vertex 4", "vertex 99999999999999999999999"), "bad vertex count"},
      {"format.ply", patched(good, "binary_little_endian", "binary_middle_endian"),
       "unknown format 'binary_middle_endian'"},
      {"big.ply", patched(good, "binary_little_endian", "binary_big_endian"),
       "binary_big_endian PLY files are not supported"},
      {"missing.ply", patched(good, "float opacity\n", "float opacitz\n"),
       "missing property 'opacity'"},
      {"rest.ply", patched(good, "f_rest_8\n", "g_rest_8\n"), "8 f_rest properties"},
      {"duplicate.ply", patched(good, "float nx\n", "float x\n"), "duplicate property 'x'"},
      {"type.ply", patched(good, "float nx\n", "half nx\n"), "unknown property type 'half'"},
      {"nan.ply", ascii_ply("1", "0 0 nan 0 0 0 0 0 0 0 1 0 0 0\n"),
       "every Gaussian is left out: vertex 0: property 'z' is not a finite float"},
      {"large.ply", ascii_ply("1", "0 0 1e39 0 0 0 0 0 0 0 1 0 0 0\n"),
       "every Gaussian is left out: vertex 0: property 'z' is not a finite float"},
      {"word.ply", ascii_ply("1", "0 zero 0 0 0 0 0 0 0 0 1 0 0 0\n"),
       "vertex 0: property 'y' has a bad number 'zero'"},
      {"short.ply", ascii_ply("2", row), "truncated: the data ends at vertex 1"},
      {"shortline.ply", ascii_ply("2", "1 2 3\n" + row),
       "vertex 0: its line ends before property 'f_dc_0'"},
      {"extra.ply", ascii_ply("1", row + row),
       "holds more vertex data than the header's count of 1"},
      {"longline.ply", ascii_ply("2", "0 0 0 0 0 0 0 0 0 0 1 0 0 0 9\n" + row),
       "vertex 0: its line holds more values than the vertex has properties (from '9')"},
      {"face.ply",
       "ply\nformat ascii 1.0\nelement face 0\nproperty list uchar int vertex_indices\n"
       "end_header\n",
       "the first element is 'face', expected 'vertex'"},
      {"list.ply", "ply\nformat ascii 1.0\nelement vertex 1\nproperty list uchar float x\n",
       "list properties in the vertex element are not supported"},
      {"novertex.ply", "ply\nformat ascii 1.0\nend_header\n", "the header has no vertex element"},
      {"compressed.ply",
       "ply\nformat binary_little_endian 1.0\nelement chunk 1\nproperty float min_x\n"
       "element vertex 1\nproperty uint packed_position\nend_header\n",
       "a compressed PLY (element 'chunk'"},
      {"points3D.ply",
       "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n"
       "property float z\nproperty uchar red\nproperty uchar green\nproperty uchar blue\n"
       "end_header\n1 2 3 255 0 0\n",
       "has no Gaussian properties (f_dc_*, opacity, scale_*, rot_*): a point cloud"},
  };
  for (const auto& c : cases) {
    write_text(dir / c.file, c.bytes);
    const std::string message = error_message([&] { read_ply(dir / c.file); });
    EXPECT_EQ(message.rfind((dir / c.file).string() + ": ", 0), 0u) << message;
    EXPECT_NE(message.find(c.problem), std::string::npos) << message;
  }
  EXPECT_NE(error_message([&] { read_ply(dir / "absent.ply"); }).find("absent.ply: file not found"),
            std::string::npos);
}

// `cloud` without its Gaussian `index`.
SplatCloud without(SplatCloud cloud, size_t index) {
  const size_t count = cloud.size();
  for (std::vector<float>* values : {&cloud.positions, &cloud.sh_dc, &cloud.sh_rest, &cloud.opacity,
                                     &cloud.log_scales, &cloud.rotations, &cloud.filter_3d}) {
    const size_t width = values->size() / count;
    values->erase(values->begin() + std::ptrdiff_t(index * width),
                  values->begin() + std::ptrdiff_t((index + 1) * width));
  }
  return cloud;
}

// A vertex holding a value that is not a finite float (a training diverged in part: 3DGS does not
// check) is left out with a warning, as viewers still open such a file; the others load in order.
TEST(Ply, VerticesHoldingNonFiniteValuesAreLeftOutWithAWarning) {
  TempDir dir;
  const SplatCloud cloud = make_cloud(1, 4, true);
  write_ply(dir / "good.ply", cloud);
  std::string bytes = read_file(dir / "good.ply");
  const float inf = std::numeric_limits<float>::infinity();
  // Vertex 1's x, after vertex 0's 27 floats (3 + 3 normals + 3 + 9 + 1 + 3 + 4 + 1).
  std::memcpy(&bytes[header_of(bytes).size() + 27 * sizeof(float)], &inf, sizeof(float));
  testing::CapturedLog log;
  EXPECT_TRUE(
      testing::contains(error_message([&] { parse_ply(bytes, "own.ply", NonFinite::Refuse); }),
                        "own.ply: vertex 1: property 'x' is not a finite float (inf)"));
  expect_same(parse_ply(bytes, "part.ply"), without(cloud, 1));
  EXPECT_EQ(log.count("part.ply: 1 of 4 Gaussians are left out for holding a value that is not "
                      "finite (first, vertex 1: property 'x' is not a finite float (inf))"),
            1u)
      << log.text();

  const std::string points =
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
      "property float z\nproperty uchar red\nproperty uchar green\nproperty uchar blue\n"
      "end_header\n1 2 3 10 20 30\n4 nan 6 0 0 0\n7 8 9 40 50 60\n";
  const PointCloud read = parse_point_ply(points, "points.ply");
  ASSERT_EQ(read.positions.size(), 2u);
  EXPECT_EQ(read.positions[1].x, 7);
  EXPECT_EQ(read.colors[1], (std::array<uint8_t, 3>{40, 50, 60}));
  EXPECT_EQ(log.count("points.ply: 1 of 3 points are left out"), 1u) << log.text();
}

TEST(Ply, WriterRejectsInconsistentOrNonFiniteClouds) {
  TempDir dir;
  SplatCloud short_opacity = make_cloud(2, 3, false);
  short_opacity.opacity.pop_back();
  EXPECT_NE(error_message([&] {
              write_ply(dir / "sizes.ply", short_opacity);
            }).find("sizes.ply: the array of 'opacity' holds 2 values, expected 3"),
            std::string::npos);
  SplatCloud bad_degree = make_cloud(0, 1, false);
  bad_degree.sh_degree = 4;
  EXPECT_NE(error_message([&] {
              write_ply_filter_baked(dir / "degree.ply", bad_degree);
            }).find("degree.ply: SH degree 4 is outside 0..3"),
            std::string::npos);
  SplatCloud nan_scale = make_cloud(1, 3, true);
  nan_scale.log_scales[7] = std::nanf("");
  EXPECT_NE(error_message([&] {
              write_ply(dir / "nan.ply", nan_scale);
            }).find("nan.ply: Gaussian 2: 'scale_1' is not finite"),
            std::string::npos);
  EXPECT_TRUE(fs::is_empty(dir.path()));
}

}  // namespace
}  // namespace iesrgs
