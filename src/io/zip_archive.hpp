#pragma once
// Reading members of a zip archive held in memory (the container of torch.save's default
// format): the central directory, zip64 extensions, stored and deflated members, CRC-checked.
#include <cstdint>
#include <map>
#include <string>
#include <string_view>
#include <vector>

namespace iesrgs {

class ZipArchive {
 public:
  // Parses the central directory of `bytes`, which must outlive the archive. Throws FormatError.
  explicit ZipArchive(std::string_view bytes);

  std::vector<std::string> names() const;
  bool contains(const std::string& name) const { return members_.count(name) != 0; }
  // The uncompressed contents of member `name`. Throws FormatError.
  std::string read(const std::string& name) const;
  // Checks every member against its CRC (a readable archive whose bytes were damaged later).
  // Throws FormatError naming the first member that fails.
  void check_all() const;

 private:
  struct Member {
    uint16_t method = 0;
    uint16_t flags = 0;
    uint32_t crc = 0;
    uint64_t compressed_size = 0;
    uint64_t size = 0;
    uint64_t local_header = 0;
  };
  struct Directory {
    uint64_t count = 0;
    uint64_t offset = 0;
  };

  Directory find_directory() const;
  Directory zip64_directory(size_t end_record) const;
  size_t read_member(size_t position);
  std::string_view member_data(const Member& member) const;
  std::string inflated(const std::string& name, const Member& member) const;

  std::string_view bytes_;
  std::map<std::string, Member> members_;
};

}  // namespace iesrgs
