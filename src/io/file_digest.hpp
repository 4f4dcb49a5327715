#pragma once
// Content digests for cache keys. A cached stage must follow what its inputs contain, not where
// they lie or when they were written: a copied or re-provisioned dataset keeps its caches, an
// image edited in place invalidates them.
#include <filesystem>
#include <string>
#include <vector>

namespace iesrgs {

// 16 hex digits of FNV-1a over the file's 64-bit words (then its tail bytes), seeded with its
// size; "-" when the path is empty or names no file. Throws an Error naming an unreadable file.
std::string file_digest(const std::filesystem::path& path);

// One digest of several files' names and contents, in the given order.
std::string files_digest(const std::vector<std::filesystem::path>& paths);

}  // namespace iesrgs
