#pragma once
/// The one check every reader of a user's file makes first: it is a regular file. A directory,
/// a FIFO (which would block the reader) or a device (/dev/zero: endless) is refused with what it
/// is, a missing file as missing.
#include <filesystem>
#include <string>

#include "fieldpath/common/errors.h"

namespace fieldpath::common {

/// Throws InputError "FILE: no such WHAT" / "FILE: is a directory, expected a WHAT" / "FILE: not
/// a regular file (a FIFO, socket or device), expected a WHAT" unless `file` is a regular file.
inline void requireRegularFile(const std::filesystem::path& file, const std::string& what = "file") {
  std::error_code ec;
  const std::filesystem::file_status status = std::filesystem::status(file, ec);
  if (std::filesystem::is_regular_file(status)) return;
  if (std::filesystem::is_directory(status))
    throw InputError(file.string() + ": is a directory, expected a " + what);
  if (std::filesystem::exists(status))
    throw InputError(file.string() + ": not a regular file (a FIFO, socket or device), expected a " +
                     what);
  throw InputError(file.string() + ": no such " + what);
}

}  // namespace fieldpath::common
