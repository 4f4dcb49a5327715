#include "io/ply.hpp"

#include <algorithm>
#include <cctype>
#include <cfloat>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <limits>
#include <optional>
#include <string>
#include <unordered_map>
#include <unordered_set>

#include "core/error.hpp"
#include "io/atomic_file.hpp"
#include "io/non_finite_records.hpp"

namespace iesrgs {

namespace fs = std::filesystem;

namespace {

static_assert(__BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__,
              "binary PLY values are copied as they are, which needs a little-endian host");

constexpr std::string_view kRestPrefix = "f_rest_";
constexpr char kFilterName[] = "filter_3D";
constexpr std::string_view kBackgroundComment = "background";

size_t rest_per_channel(int sh_degree) {
  return size_t((sh_degree + 1) * (sh_degree + 1) - 1);
}

// Where one PLY property lives in a SplatCloud: (cloud.*field)[gaussian * width + offset]. The
// normals have no field: written as zeros, skipped when read.
struct Slot {
  std::string name;
  std::vector<float> SplatCloud::*field = nullptr;
  size_t width = 0, offset = 0;
};

void add_slots(std::vector<Slot>& slots, std::initializer_list<const char*> names,
               std::vector<float> SplatCloud::*field) {
  size_t offset = 0;
  for (const char* name : names) slots.push_back({name, field, names.size(), offset++});
}

// Every property in 3DGS's file order.
std::vector<Slot> layout(int sh_degree, bool with_filter_3d) {
  std::vector<Slot> slots;
  add_slots(slots, {"x", "y", "z"}, &SplatCloud::positions);
  add_slots(slots, {"nx", "ny", "nz"}, nullptr);
  add_slots(slots, {"f_dc_0", "f_dc_1", "f_dc_2"}, &SplatCloud::sh_dc);
  // 3DGS flattens its (N, 3, K-1) transpose of features_rest: f_rest_j is channel j / (K-1),
  // coefficient j % (K-1).
  const size_t rest = rest_per_channel(sh_degree);
  for (size_t j = 0; j < 3 * rest; ++j)
    slots.push_back({std::string(kRestPrefix) + std::to_string(j), &SplatCloud::sh_rest, 3 * rest,
                     (j % rest) * 3 + j / rest});
  add_slots(slots, {"opacity"}, &SplatCloud::opacity);
  add_slots(slots, {"scale_0", "scale_1", "scale_2"}, &SplatCloud::log_scales);
  add_slots(slots, {"rot_0", "rot_1", "rot_2", "rot_3"}, &SplatCloud::rotations);
  if (with_filter_3d) add_slots(slots, {kFilterName}, &SplatCloud::filter_3d);
  return slots;
}

// ---- writing ----

// The cloud's layout, after checking that its arrays match it.
std::vector<Slot> checked_layout(const SplatCloud& cloud, const fs::path& path) {
  if (cloud.sh_degree < 0 || cloud.sh_degree > kMaxCloudShDegree)
    fail_file(path,
              fmt::format("SH degree {} is outside 0..{}", cloud.sh_degree, kMaxCloudShDegree));
  std::vector<Slot> slots = layout(cloud.sh_degree, cloud.has_filter_3d());
  const size_t count = cloud.size();
  for (const Slot& slot : slots) {
    if (!slot.field || slot.offset != 0) continue;
    const size_t size = (cloud.*slot.field).size();
    if (size != count * slot.width)
      fail_file(path, fmt::format("the array of '{}' holds {} values, expected {} for {} Gaussians",
                                  slot.name, size, count * slot.width, count));
  }
  return slots;
}

std::string header_text(const SplatCloud& cloud, const std::vector<Slot>& slots) {
  std::string text = "ply\nformat binary_little_endian 1.0\n";
  if (const auto& background = cloud.background)
    text += fmt::format("comment {} {} {} {}\n", kBackgroundComment, (*background)[0],
                        (*background)[1], (*background)[2]);
  text += fmt::format("element vertex {}\n", cloud.size());
  for (const Slot& slot : slots) text += "property float " + slot.name + "\n";
  return text + "end_header\n";
}

void write_body(std::ostream& out, const SplatCloud& cloud, const std::vector<Slot>& slots,
                const fs::path& path) {
  std::vector<float> row(slots.size());
  for (size_t i = 0; i < cloud.size(); ++i) {
    for (size_t p = 0; p < slots.size(); ++p) {
      const Slot& slot = slots[p];
      row[p] = slot.field ? (cloud.*slot.field)[i * slot.width + slot.offset] : 0.f;
      if (!std::isfinite(row[p]))
        fail_file(path, fmt::format("Gaussian {}: '{}' is not finite", i, slot.name));
    }
    out.write(reinterpret_cast<const char*>(row.data()),
              std::streamsize(row.size() * sizeof(float)));
  }
}

// log(exp(a) + exp(b)) without overflow; exact when one side is -inf.
double log_add_exp(double a, double b) {
  const double hi = std::max(a, b), lo = std::min(a, b);
  if (hi == -std::numeric_limits<double>::infinity()) return hi;
  return hi + std::log1p(std::exp(lo - hi));
}

double softplus(double x) {
  return log_add_exp(0, x);
}

// logit(sigmoid(logit_p) * exp(log_c)) for log_c <= 0, in log space so that it stays finite when
// the product is close to 1 and returns logit_p unchanged when log_c is 0.
double scaled_logit(double logit_p, double log_c) {
  const double log_p = log_c - softplus(-logit_p);
  const double log_one_minus_p =
      log_add_exp(std::log(-std::expm1(log_c)), log_c - softplus(logit_p));
  return log_p - log_one_minus_p;
}

// ---- reading ----

enum class Scalar { kInt8, kUint8, kInt16, kUint16, kInt32, kUint32, kFloat32, kFloat64 };

std::optional<Scalar> scalar_named(std::string_view name) {
  static const std::pair<std::string_view, Scalar> kNames[] = {
      {"char", Scalar::kInt8},      {"int8", Scalar::kInt8},       {"uchar", Scalar::kUint8},
      {"uint8", Scalar::kUint8},    {"short", Scalar::kInt16},     {"int16", Scalar::kInt16},
      {"ushort", Scalar::kUint16},  {"uint16", Scalar::kUint16},   {"int", Scalar::kInt32},
      {"int32", Scalar::kInt32},    {"uint", Scalar::kUint32},     {"uint32", Scalar::kUint32},
      {"float", Scalar::kFloat32},  {"float32", Scalar::kFloat32}, {"double", Scalar::kFloat64},
      {"float64", Scalar::kFloat64}};
  for (const auto& [text, scalar] : kNames)
    if (text == name) return scalar;
  return std::nullopt;
}

size_t scalar_size(Scalar scalar) {
  switch (scalar) {
    case Scalar::kInt8:
    case Scalar::kUint8:
      return 1;
    case Scalar::kInt16:
    case Scalar::kUint16:
      return 2;
    case Scalar::kInt32:
    case Scalar::kUint32:
    case Scalar::kFloat32:
      return 4;
    case Scalar::kFloat64:
      return 8;
  }
  return 0;
}

template <typename T>
double load(const char* bytes) {
  T value;
  std::memcpy(&value, bytes, sizeof(T));
  return double(value);
}

double load_scalar(const char* bytes, Scalar scalar) {
  switch (scalar) {
    case Scalar::kInt8:
      return load<int8_t>(bytes);
    case Scalar::kUint8:
      return load<uint8_t>(bytes);
    case Scalar::kInt16:
      return load<int16_t>(bytes);
    case Scalar::kUint16:
      return load<uint16_t>(bytes);
    case Scalar::kInt32:
      return load<int32_t>(bytes);
    case Scalar::kUint32:
      return load<uint32_t>(bytes);
    case Scalar::kFloat32:
      return load<float>(bytes);
    case Scalar::kFloat64:
      return load<double>(bytes);
  }
  return 0;
}

struct Property {
  std::string name;
  Scalar type;
};

struct Header {
  bool ascii = false;
  std::optional<std::array<float, 3>> background;
  uint64_t vertex_count = 0;
  std::vector<Property> properties;  // of the vertex element
  bool vertex_last = true;           // no element follows the vertices
  size_t body_offset = 0;
};

// A token from the file made safe to quote in a one-line message.
std::string quote_token(std::string_view token) {
  constexpr size_t kMaxQuoted = 40;
  std::string text(token.substr(0, kMaxQuoted));
  for (char& c : text)
    if (!std::isprint(static_cast<unsigned char>(c))) c = '?';
  return "'" + text + (token.size() > kMaxQuoted ? "...'" : "'");
}

std::vector<std::string_view> split_words(std::string_view line) {
  std::vector<std::string_view> words;
  size_t pos = 0;
  while (pos < line.size()) {
    const size_t start = line.find_first_not_of(" \t\r", pos);
    if (start == std::string_view::npos) break;
    pos = std::min(line.find_first_of(" \t\r", start), line.size());
    words.push_back(line.substr(start, pos - start));
  }
  return words;
}

// Reads the header line by line, up to and including end_header, where the body starts.
class HeaderParser {
 public:
  HeaderParser(std::string_view bytes, const fs::path& name) : bytes_(bytes), name_(name) {}

  Header parse() {
    if (next_line() != std::vector<std::string_view>{"ply"})
      fail_file(name_, "not a PLY file (the first line is not 'ply')");
    while (true) {
      const std::vector<std::string_view> words = next_line();
      if (!words.empty() && words[0] == "comment") parse_comment(words);
      if (words.empty() || words[0] == "comment" || words[0] == "obj_info") continue;
      if (words[0] == "end_header") break;
      if (words[0] == "format") {
        parse_format(words);
      } else if (words[0] == "element") {
        parse_element(words);
      } else if (words[0] == "property") {
        parse_property(words);
      } else {
        fail_line("unknown header keyword " + quote_token(words[0]));
      }
    }
    if (!format_seen_) fail_file(name_, "the header has no format line");
    if (!vertex_seen_) fail_file(name_, "the header has no vertex element");
    header_.body_offset = pos_;
    return header_;
  }

 private:
  std::vector<std::string_view> next_line() {
    const size_t end = bytes_.find('\n', pos_);
    if (end == std::string_view::npos) fail_file(name_, "truncated header (no end_header line)");
    const std::string_view line = bytes_.substr(pos_, end - pos_);
    pos_ = end + 1;
    ++line_number_;
    return split_words(line);
  }

  [[noreturn]] void fail_line(const std::string& problem) const {
    fail_file(name_, fmt::format("header line {}: {}", line_number_, problem));
  }

  // "comment background r g b" with each in [0, 1]; any other comment, this one malformed
  // included, is a remark for people and skipped as other readers skip it.
  void parse_comment(const std::vector<std::string_view>& words) {
    if (words.size() != 5 || words[1] != kBackgroundComment) return;
    std::array<float, 3> background{};
    for (size_t c = 0; c < 3; ++c) {
      const char* end = words[2 + c].data() + words[2 + c].size();
      const auto [ptr, ec] = std::from_chars(words[2 + c].data(), end, background[c]);
      if (ec != std::errc() || ptr != end || !(background[c] >= 0 && background[c] <= 1)) return;
    }
    header_.background = background;
  }

  void parse_format(const std::vector<std::string_view>& words) {
    if (words.size() != 3 || words[2] != "1.0") fail_line("expected 'format <type> 1.0'");
    if (words[1] == "binary_big_endian")
      fail_line("binary_big_endian PLY files are not supported (use binary_little_endian)");
    if (words[1] != "ascii" && words[1] != "binary_little_endian")
      fail_line("unknown format " + quote_token(words[1]));
    header_.ascii = words[1] == "ascii";
    format_seen_ = true;
  }

  void parse_element(const std::vector<std::string_view>& words) {
    if (words.size() != 3) fail_line("expected 'element <name> <count>'");
    in_vertex_ = !vertex_seen_;
    if (!in_vertex_) {  // later elements follow the vertex data and are not read
      header_.vertex_last = false;
      return;
    }
    if (words[1] == "chunk")
      fail_line(
          "a compressed PLY (element 'chunk', then packed vertices, as SuperSplat and "
          "splat-transform write it), which is not read here; convert it to the 3DGS layout first");
    if (words[1] != "vertex")
      fail_line("the first element is " + quote_token(words[1]) + ", expected 'vertex'");
    const char* end = words[2].data() + words[2].size();
    const auto [ptr, ec] = std::from_chars(words[2].data(), end, header_.vertex_count);
    if (ec != std::errc() || ptr != end) fail_line("bad vertex count " + quote_token(words[2]));
    vertex_seen_ = true;
  }

  void parse_property(const std::vector<std::string_view>& words) {
    if (!vertex_seen_) fail_line("property before any element");
    if (!in_vertex_) return;
    if (words.size() >= 2 && words[1] == "list")
      fail_line("list properties in the vertex element are not supported");
    if (words.size() != 3) fail_line("expected 'property <type> <name>'");
    const std::optional<Scalar> type = scalar_named(words[1]);
    if (!type) fail_line("unknown property type " + quote_token(words[1]));
    header_.properties.push_back({std::string(words[2]), *type});
  }

  std::string_view bytes_;
  const fs::path& name_;
  size_t pos_ = 0;
  size_t line_number_ = 0;
  Header header_;
  bool format_seen_ = false, vertex_seen_ = false, in_vertex_ = false;
};

bool is_rest_coefficient(const Property& property) {
  return std::string_view(property.name).substr(0, kRestPrefix.size()) == kRestPrefix;
}

int infer_sh_degree(const Header& header, const fs::path& name) {
  const size_t rest =
      std::count_if(header.properties.begin(), header.properties.end(), is_rest_coefficient);
  for (int degree = 0; degree <= kMaxCloudShDegree; ++degree)
    if (rest == 3 * rest_per_channel(degree)) return degree;
  fail_file(name,
            fmt::format("{} f_rest properties; expected 0, 9, 24 or 45 (SH degree 0 to 3)", rest));
}

// The slot of each vertex property in file order (nullptr for properties not stored).
std::vector<const Slot*> match_properties(const Header& header, const std::vector<Slot>& slots,
                                          const fs::path& name) {
  std::unordered_map<std::string_view, const Slot*> by_name;
  for (const Slot& slot : slots) by_name[slot.name] = &slot;
  std::unordered_set<std::string_view> seen;
  std::vector<const Slot*> targets;
  for (const Property& property : header.properties) {
    if (!seen.insert(property.name).second)
      fail_file(name, "duplicate property " + quote_token(property.name));
    const auto it = by_name.find(property.name);
    targets.push_back(it != by_name.end() && it->second->field ? it->second : nullptr);
  }
  if (!seen.count("opacity") && !seen.count("scale_0") && !seen.count("f_dc_0"))
    fail_file(name,
              "has no Gaussian properties (f_dc_*, opacity, scale_*, rot_*): a point cloud, not a "
              "Gaussian splatting model");
  for (const Slot& slot : slots)
    if (slot.field && !seen.count(slot.name))
      fail_file(name, "missing property " + quote_token(slot.name));
  return targets;
}

// Rejects a vertex count the body cannot hold before anything is allocated for it. An ascii value
// takes at least two bytes (a digit and a separator), the very last one at least one.
void check_count_fits(const Header& header, size_t body_size, const fs::path& name) {
  size_t per_vertex = 0;
  for (const Property& property : header.properties)
    per_vertex += header.ascii ? 2 : scalar_size(property.type);
  const size_t room = header.ascii ? body_size + 1 : body_size;
  if (header.vertex_count > room / per_vertex)
    fail_file(name, fmt::format("{} vertices do not fit in the {} bytes after the header "
                                "(truncated file or wrong count)",
                                header.vertex_count, body_size));
}

SplatCloud allocate(const Header& header, const std::vector<Slot>& slots, int sh_degree) {
  SplatCloud cloud;
  cloud.sh_degree = sh_degree;
  for (const Slot& slot : slots)
    if (slot.field) (cloud.*slot.field).resize(header.vertex_count * slot.width);
  return cloud;
}

// Values of an ascii body: a line per vertex, as the format has it, so that a value too many or
// too few on one line is named there instead of shifting every later vertex.
class AsciiValues {
 public:
  AsciiValues(std::string_view body, const fs::path& name) : body_(body), name_(name) {}

  void begin_vertex(size_t vertex) {
    pos_ = body_.find_first_not_of(" \t\r\n", pos_);  // blank lines between vertices pass
    if (pos_ == std::string_view::npos) fail_truncated(vertex);
  }

  double next(size_t vertex, const Property& property) {
    const size_t start = std::min(body_.find_first_not_of(" \t\r", pos_), body_.size());
    if (start == body_.size()) fail_truncated(vertex);
    if (body_[start] == '\n')
      fail_file(name_, fmt::format("vertex {}: its line ends before property {}", vertex,
                                   quote_token(property.name)));
    pos_ = std::min(body_.find_first_of(" \t\r\n", start), body_.size());
    const std::string_view token = body_.substr(start, pos_ - start);
    // from_chars takes no leading '+', which C's strtod (and so other PLY writers' readers) do.
    const std::string_view digits =
        token.size() > 1 && token[0] == '+' && token[1] != '-' ? token.substr(1) : token;
    double value = 0;
    const auto [ptr, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), value);
    if (ec != std::errc() || ptr != digits.data() + digits.size())
      fail_file(name_, fmt::format("vertex {}: property {} has a bad number {}", vertex,
                                   quote_token(property.name), quote_token(token)));
    return value;
  }

  void end_vertex(size_t vertex) {
    pos_ = std::min(body_.find_first_not_of(" \t\r", pos_), body_.size());
    if (pos_ == body_.size() || body_[pos_] == '\n') return;
    const size_t end = std::min(body_.find_first_of(" \t\r\n", pos_), body_.size());
    fail_file(name_, fmt::format("vertex {}: its line holds more values than the vertex has "
                                 "properties (from {})",
                                 vertex, quote_token(body_.substr(pos_, end - pos_))));
  }

  // After the last vertex of a file whose header declares nothing after them.
  void end_body(uint64_t count) const {
    if (body_.find_first_not_of(" \t\r\n", pos_) != std::string_view::npos)
      fail_file(name_, fmt::format("holds more vertex data than the header's count of {}", count));
  }

 private:
  [[noreturn]] void fail_truncated(size_t vertex) const {
    fail_file(name_, fmt::format("truncated: the data ends at vertex {}", vertex));
  }

  std::string_view body_;
  const fs::path& name_;
  size_t pos_ = 0;
};

// Values of a binary_little_endian body, whose size check_count_fits has checked.
class BinaryValues {
 public:
  explicit BinaryValues(std::string_view body) : next_(body.data()) {}

  void begin_vertex(size_t) {}
  void end_vertex(size_t) {}
  void end_body(uint64_t) const {}

  double next(size_t, const Property& property) {
    const double value = load_scalar(next_, property.type);
    next_ += scalar_size(property.type);
    return value;
  }

 private:
  const char* next_;
};

bool is_finite_float(double value) {
  return std::fabs(value) <= FLT_MAX;
}

std::string not_finite(size_t vertex, std::string_view property, double value) {
  return fmt::format("vertex {}: property '{}' is not a finite float ({})", vertex, property,
                     value);
}

// Each vertex is written over the first row not yet kept, and the arrays cut to those kept.
template <typename Values>
void read_body(Values values, const Header& header, const std::vector<const Slot*>& targets,
               SplatCloud& cloud, const fs::path& name, NonFinite non_finite) {
  NonFiniteRecords left_out(name, "Gaussian", non_finite);
  size_t kept = 0;
  for (size_t i = 0; i < header.vertex_count; ++i) {
    values.begin_vertex(i);
    bool finite = true;
    for (size_t p = 0; p < header.properties.size(); ++p) {
      const double value = values.next(i, header.properties[p]);
      const Slot* slot = targets[p];
      if (!slot || !finite) continue;
      if (!is_finite_float(value)) {
        left_out.add([&] { return not_finite(i, slot->name, value); });
        finite = false;
        continue;
      }
      (cloud.*slot->field)[kept * slot->width + slot->offset] = float(value);
    }
    values.end_vertex(i);
    kept += finite;
  }
  if (header.vertex_last) values.end_body(header.vertex_count);
  left_out.report(header.vertex_count);
  if (kept == header.vertex_count) return;
  for (std::vector<float>* values : {&cloud.positions, &cloud.sh_dc, &cloud.sh_rest, &cloud.opacity,
                                     &cloud.log_scales, &cloud.rotations, &cloud.filter_3d})
    values->resize(values->size() / header.vertex_count * kept);
}

// ---- point clouds ----

constexpr const char* kPointProperties[6] = {"x", "y", "z", "red", "green", "blue"};
constexpr size_t kNoProperty = SIZE_MAX;
constexpr uint8_t kGrey = 128;  // the colour of points stored without one

// Where each of kPointProperties sits among the vertex properties; colours may be absent.
std::array<size_t, 6> point_property_indices(const Header& header, const fs::path& name) {
  std::array<size_t, 6> index{};
  for (size_t k = 0; k < index.size(); ++k) {
    const auto it = std::find_if(header.properties.begin(), header.properties.end(),
                                 [&](const Property& p) { return p.name == kPointProperties[k]; });
    index[k] = it == header.properties.end() ? kNoProperty : size_t(it - header.properties.begin());
    if (k < 3 && index[k] == kNoProperty)
      fail_file(name, fmt::format("missing property '{}' (a point cloud has x y z, and may have "
                                  "red green blue)",
                                  kPointProperties[k]));
  }
  return index;
}

// fmin / fmax also map NaN to a byte.
uint8_t color_byte(double value, Scalar type) {
  const bool unit = type == Scalar::kFloat32 || type == Scalar::kFloat64;
  return uint8_t(std::lround(std::fmin(std::fmax(unit ? value * 255 : value, 0.0), 255.0)));
}

template <typename Values>
PointCloud read_points(Values values, const Header& header, const std::array<size_t, 6>& index,
                       const fs::path& name) {
  PointCloud points;
  points.positions.reserve(header.vertex_count);
  points.colors.reserve(header.vertex_count);
  NonFiniteRecords left_out(name, "point");
  std::vector<double> row(header.properties.size());
  for (size_t i = 0; i < header.vertex_count; ++i) {
    values.begin_vertex(i);
    for (size_t p = 0; p < row.size(); ++p) row[p] = values.next(i, header.properties[p]);
    values.end_vertex(i);
    const auto broken = std::find_if(index.begin(), index.begin() + 3,
                                     [&](size_t p) { return !is_finite_float(row[p]); });
    if (broken != index.begin() + 3) {
      left_out.add(
          [&] { return not_finite(i, kPointProperties[broken - index.begin()], row[*broken]); });
      continue;
    }
    points.positions.push_back({row[index[0]], row[index[1]], row[index[2]]});
    std::array<uint8_t, 3>& color = points.colors.emplace_back();
    for (size_t c = 0; c < 3; ++c) {
      const size_t p = index[3 + c];
      color[c] = p == kNoProperty ? kGrey : color_byte(row[p], header.properties[p].type);
    }
  }
  if (header.vertex_last) values.end_body(header.vertex_count);
  left_out.report(header.vertex_count);
  return points;
}

}  // namespace

void write_ply(const fs::path& path, const SplatCloud& cloud) {
  const std::vector<Slot> slots = checked_layout(cloud, path);
  write_atomically(path, [&](const fs::path& tmp) {
    std::ofstream out(tmp, std::ios::binary);
    out << header_text(cloud, slots);
    write_body(out, cloud, slots, path);
    close_written(out, path);
  });
}

void check_splat_cloud(const SplatCloud& cloud, const fs::path& path) {
  checked_layout(cloud, path);
}

// In log space: log of sqrt(s^2 + f^2) is half of log_add_exp(2 log s, 2 log f).
SplatCloud bake_filter_3d(SplatCloud cloud) {
  for (size_t i = 0; i < cloud.filter_3d.size(); ++i) {
    const double log_filter = std::log(std::fabs(double(cloud.filter_3d[i])));
    double log_opacity_factor = 0;
    for (size_t k = 0; k < 3; ++k) {
      float& log_scale = cloud.log_scales[3 * i + k];
      const double widened = 0.5 * log_add_exp(2.0 * log_scale, 2.0 * log_filter);
      log_opacity_factor += log_scale - widened;
      log_scale = float(widened);
    }
    cloud.opacity[i] = float(scaled_logit(cloud.opacity[i], log_opacity_factor));
  }
  cloud.filter_3d.clear();
  return cloud;
}

void write_ply_filter_baked(const fs::path& path, const SplatCloud& cloud) {
  check_splat_cloud(cloud, path);  // before baking indexes the arrays
  write_ply(path, bake_filter_3d(cloud));
}

SplatCloud read_ply(const fs::path& path, NonFinite non_finite) {
  return parse_ply(read_file(path), path, non_finite);
}

SplatCloud parse_ply(std::string_view bytes, const fs::path& name, NonFinite non_finite) {
  const Header header = HeaderParser(bytes, name).parse();
  const int sh_degree = infer_sh_degree(header, name);
  const bool has_filter = std::any_of(header.properties.begin(), header.properties.end(),
                                      [](const Property& p) { return p.name == kFilterName; });
  const std::vector<Slot> slots = layout(sh_degree, has_filter);
  const std::vector<const Slot*> targets = match_properties(header, slots, name);
  const std::string_view body = bytes.substr(header.body_offset);
  check_count_fits(header, body.size(), name);
  SplatCloud cloud = allocate(header, slots, sh_degree);
  if (header.ascii)
    read_body(AsciiValues(body, name), header, targets, cloud, name, non_finite);
  else
    read_body(BinaryValues(body), header, targets, cloud, name, non_finite);
  cloud.antialiased = has_filter;
  cloud.background = header.background;
  return cloud;
}

PointCloud read_point_ply(const fs::path& path) {
  return parse_point_ply(read_file(path), path);
}

PointCloud parse_point_ply(std::string_view bytes, const fs::path& name) {
  const Header header = HeaderParser(bytes, name).parse();
  // First: check_count_fits needs properties, which this finds at least three of.
  const std::array<size_t, 6> index = point_property_indices(header, name);
  const std::string_view body = bytes.substr(header.body_offset);
  check_count_fits(header, body.size(), name);
  if (header.ascii) return read_points(AsciiValues(body, name), header, index, name);
  return read_points(BinaryValues(body), header, index, name);
}

}  // namespace iesrgs
