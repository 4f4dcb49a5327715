#pragma once
// Messages said once per process: a scene loaded twice (`run` reads it at two resolutions), or a
// stage checked again, says what it found once.
#include <string>

namespace iesrgs {

void warn_once(const std::string& message);
void debug_once(const std::string& message);

}  // namespace iesrgs
