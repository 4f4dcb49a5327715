#pragma once
// File name helpers shared by the commands and readers.
#include <algorithm>
#include <cctype>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace iesrgs {

// The absolute path as the file system resolves it (links, "..", one folder named two ways), for
// telling whether two paths name one file; absolute but unresolved when it cannot be resolved.
// Made absolute first: weakly_canonical leaves a relative path whose first part does not exist
// relative.
inline std::filesystem::path resolved_path(const std::filesystem::path& path) {
  std::error_code ec;
  const std::filesystem::path absolute = std::filesystem::absolute(path, ec);
  const std::filesystem::path canonical = std::filesystem::weakly_canonical(absolute, ec);
  return ec ? absolute : canonical;
}

// The path an environment variable holds; none when it is unset or empty.
inline std::optional<std::filesystem::path> env_path(const char* variable) {
  const char* value = std::getenv(variable);
  if (value == nullptr || *value == '\0') return std::nullopt;
  return std::filesystem::path(value);
}

// The XDG cache folder of `app`: $XDG_CACHE_HOME/<app>, else ~/.cache/<app>; none without either.
inline std::optional<std::filesystem::path> user_cache_dir(const std::string& app) {
  if (auto cache = env_path("XDG_CACHE_HOME")) return *cache / app;
  if (auto home = env_path("HOME")) return *home / ".cache" / app;
  return std::nullopt;
}

// ".png" for "a.PNG": file types are told apart by extension in any case.
inline std::string lowercase_extension(const std::filesystem::path& path) {
  std::string extension = path.extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(),
                 [](unsigned char c) { return char(std::tolower(c)); });
  return extension;
}

// The spellings of the image extensions tried when a name comes without one: file systems tell
// ".png" from ".PNG", which is_image_file does not.
inline const std::vector<const char*> kImageExtensionSpellings = {".png", ".jpg", ".jpeg",
                                                                  ".PNG", ".JPG", ".JPEG"};

// PNG or JPEG by name, the images every reader here decodes.
inline bool is_image_file(const std::filesystem::path& path) {
  const std::string extension = lowercase_extension(path);
  return extension == ".png" || extension == ".jpg" || extension == ".jpeg";
}

// `path` as one word of a POSIX shell command: as it is when it needs no quoting, else in single
// quotes (a quote inside as '\''), so that a command printed for the user runs as printed.
inline std::string shell_word(const std::filesystem::path& path) {
  const std::string text = path.string();
  const bool plain = !text.empty() && std::all_of(text.begin(), text.end(), [](unsigned char c) {
    return std::isalnum(c) || (c != '\0' && std::strchr("/._-+,:=@%", c) != nullptr);
  });
  if (plain) return text;
  std::string quoted = "'";
  for (const char c : text) quoted += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return quoted + "'";
}

}  // namespace iesrgs
