#pragma once
// Content digests for cache keys. A cached stage must follow what its inputs contain, not where
// they lie or when they were written: a copied or re-provisioned dataset keeps its caches, an
// image edited in place invalidates them.
#include <filesystem>
#include <string>
#include <string_view>

namespace iesrgs {

// 16 hex digits of FNV-1a over the file's 64-bit words (then its tail bytes), seeded with its
// size; "-" when the path is empty or names no file. Throws an Error naming an unreadable file.
std::string file_digest(const std::filesystem::path& path);

// The same digest of bytes in memory (a cache key's text).
std::string bytes_digest(std::string_view bytes);

// One digest of the regular files directly in `dir`, by name and content (a model package's
// files); "-" when the folder is absent.
std::string directory_digest(const std::filesystem::path& dir);

}  // namespace iesrgs
