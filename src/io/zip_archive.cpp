#include "io/zip_archive.hpp"

#include <fmt/format.h>
#include <zlib.h>

#include <algorithm>
#include <limits>

#include "core/byte_reader.hpp"

namespace iesrgs {

namespace {

constexpr uint32_t kEndSignature = 0x06054b50;
constexpr uint32_t kZip64EndSignature = 0x06064b50;
constexpr uint32_t kZip64LocatorSignature = 0x07064b50;
constexpr uint32_t kDirectorySignature = 0x02014b50;
constexpr uint32_t kLocalSignature = 0x04034b50;
constexpr size_t kEndRecordSize = 22;
constexpr size_t kZip64LocatorSize = 20;
constexpr uint16_t kZip64ExtraId = 0x0001;
constexpr uint16_t kStored = 0;
constexpr uint16_t kDeflated = 8;
constexpr uint16_t kEncrypted = 1;
// Deflate cannot expand data by more than about 1032:1, so a larger claimed size is corrupt.
constexpr uint64_t kMaxDeflateRatio = 1032;

// Sizes and the offset that do not fit 32 bits move to the zip64 extra field, in this order.
void apply_zip64_extra(std::string_view extra, uint64_t& size, uint64_t& compressed_size,
                       uint64_t& local_header) {
  ByteReader reader(extra);
  while (reader.remaining() >= 4) {
    const auto id = reader.little<uint16_t>();
    ByteReader field(reader.take(reader.little<uint16_t>()));
    if (id != kZip64ExtraId) continue;
    for (uint64_t* value : {&size, &compressed_size, &local_header})
      if (*value == std::numeric_limits<uint32_t>::max()) *value = field.little<uint64_t>();
  }
}

std::string inflate_raw(std::string_view compressed, uint64_t size) {
  if (size > compressed.size() * kMaxDeflateRatio + 1024)
    throw FormatError("zip member claims an impossible uncompressed size");
  std::string out(size, '\0');
  z_stream stream{};
  if (inflateInit2(&stream, -MAX_WBITS) != Z_OK) throw FormatError("zlib initialisation failed");
  stream.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(compressed.data()));
  stream.avail_in = static_cast<uInt>(compressed.size());
  stream.next_out = reinterpret_cast<Bytef*>(out.data());
  stream.avail_out = static_cast<uInt>(out.size());
  const int status = inflate(&stream, Z_FINISH);
  const bool complete = status == Z_STREAM_END && stream.total_out == size;
  inflateEnd(&stream);
  if (!complete) throw FormatError("corrupt deflated zip member");
  return out;
}

// The contents of member `name` must have the size and the CRC its directory entry gives.
void check_contents(const std::string& name, uint64_t size, uint32_t crc,
                    std::string_view contents) {
  if (contents.size() != size)
    throw FormatError(fmt::format("zip member '{}' has the wrong size", name));
  if (crc32_z(0, reinterpret_cast<const Bytef*>(contents.data()), contents.size()) != crc)
    throw FormatError(fmt::format("zip member '{}' fails its CRC", name));
}

}  // namespace

ZipArchive::ZipArchive(std::string_view bytes) : bytes_(bytes) {
  const Directory directory = find_directory();
  size_t position = directory.offset;
  for (uint64_t i = 0; i < directory.count; ++i) position = read_member(position);
}

std::vector<std::string> ZipArchive::names() const {
  std::vector<std::string> names;
  for (const auto& [name, member] : members_) names.push_back(name);
  return names;
}

std::string ZipArchive::read(const std::string& name) const {
  const auto found = members_.find(name);
  if (found == members_.end()) throw FormatError(fmt::format("zip member '{}' is missing", name));
  const Member& member = found->second;
  std::string contents =
      member.method == kStored ? std::string(member_data(member)) : inflated(name, member);
  check_contents(name, member.size, member.crc, contents);
  return contents;
}

void ZipArchive::check_all() const {
  // Stored members are checked in place: a checkpoint holds hundreds of megabytes of them.
  for (const auto& [name, member] : members_)
    check_contents(name, member.size, member.crc,
                   member.method == kStored ? member_data(member) : inflated(name, member));
}

std::string ZipArchive::inflated(const std::string& name, const Member& member) const {
  if (member.method != kDeflated)
    throw FormatError(
        fmt::format("zip member '{}' uses unsupported compression {}", name, member.method));
  return inflate_raw(member_data(member), member.size);
}

ZipArchive::Directory ZipArchive::find_directory() const {
  if (bytes_.size() < kEndRecordSize) throw FormatError("too short for a zip archive");
  // The end record sits at the end, followed only by a comment of at most 65535 bytes.
  const size_t lowest = bytes_.size() - std::min(bytes_.size(), kEndRecordSize + 0xffff);
  for (size_t at = bytes_.size() - kEndRecordSize + 1; at-- > lowest;) {
    ByteReader reader(bytes_, at);
    if (reader.little<uint32_t>() != kEndSignature) continue;
    reader.take(6);  // disk numbers, entries on this disk
    Directory directory;
    directory.count = reader.little<uint16_t>();
    const auto size = reader.little<uint32_t>();
    directory.offset = reader.little<uint32_t>();
    if (directory.count == 0xffff || size == 0xffffffff || directory.offset == 0xffffffff)
      return zip64_directory(at);
    return directory;
  }
  throw FormatError("no zip end-of-central-directory record");
}

ZipArchive::Directory ZipArchive::zip64_directory(size_t end_record) const {
  if (end_record < kZip64LocatorSize) throw FormatError("zip64 locator missing");
  ByteReader locator(bytes_, end_record - kZip64LocatorSize);
  if (locator.little<uint32_t>() != kZip64LocatorSignature)
    throw FormatError("zip64 locator missing");
  locator.take(4);  // disk number
  const auto record_offset = locator.little<uint64_t>();
  if (record_offset > bytes_.size()) throw FormatError("zip64 end record out of range");
  ByteReader record(bytes_, record_offset);
  if (record.little<uint32_t>() != kZip64EndSignature)
    throw FormatError("zip64 end record missing");
  record.take(28);  // record size, versions, disk numbers, entries on this disk
  Directory directory;
  directory.count = record.little<uint64_t>();
  record.take(8);  // directory size
  directory.offset = record.little<uint64_t>();
  return directory;
}

size_t ZipArchive::read_member(size_t position) {
  if (position > bytes_.size()) throw FormatError("zip central directory out of range");
  ByteReader reader(bytes_, position);
  if (reader.little<uint32_t>() != kDirectorySignature)
    throw FormatError("corrupt zip central directory");
  reader.take(4);  // versions
  Member member;
  member.flags = reader.little<uint16_t>();
  member.method = reader.little<uint16_t>();
  reader.take(4);  // time and date
  member.crc = reader.little<uint32_t>();
  member.compressed_size = reader.little<uint32_t>();
  member.size = reader.little<uint32_t>();
  const auto name_length = reader.little<uint16_t>();
  const auto extra_length = reader.little<uint16_t>();
  const auto comment_length = reader.little<uint16_t>();
  reader.take(8);  // disk number, attributes
  member.local_header = reader.little<uint32_t>();
  std::string name(reader.take(name_length));
  apply_zip64_extra(reader.take(extra_length), member.size, member.compressed_size,
                    member.local_header);
  reader.take(comment_length);
  if (member.flags & kEncrypted)
    throw FormatError(fmt::format("zip member '{}' is encrypted", name));
  members_[std::move(name)] = member;
  return reader.position();
}

std::string_view ZipArchive::member_data(const Member& member) const {
  if (member.local_header > bytes_.size()) throw FormatError("zip member out of range");
  ByteReader reader(bytes_, member.local_header);
  if (reader.little<uint32_t>() != kLocalSignature) throw FormatError("corrupt zip member header");
  reader.take(22);  // versions, flags, method, time, date, CRC, sizes (the directory's count)
  const auto name_length = reader.little<uint16_t>();
  const auto extra_length = reader.little<uint16_t>();
  reader.take(size_t(name_length) + extra_length);
  if (member.compressed_size > reader.remaining()) throw FormatError("truncated zip member");
  return reader.take(member.compressed_size);
}

}  // namespace iesrgs
