// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// SHA-256 (FIPS 180-4) of bytes and of files: the input hashes of every
// report (README "Reports"), so that a result can be traced to the exact
// files it was made from.

#include <string>
#include <string_view>

namespace surftex {

/// Lower-case hex SHA-256 of `bytes` (64 characters).
std::string sha256_hex(std::string_view bytes);

/// Lower-case hex SHA-256 of the file at `path`, read in 1 MiB blocks (any
/// size). Throws IOError if it cannot be opened or read.
std::string sha256_file_hex(const std::string& path);

}  // namespace surftex
