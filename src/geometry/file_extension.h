// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// A path's extension in lower case (".obj", ".png"), the one rule every
// reader and writer uses to pick a format by name. Inline: the image IO
// module uses it too and resolves only what the executable exports.
#include <cctype>
#include <filesystem>
#include <string>

namespace surftex {

inline std::string lower_extension(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext;
}

}  // namespace surftex
