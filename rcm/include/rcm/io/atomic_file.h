// Whole-file reads and writes with the failure behaviour every rcm tool
// needs: a failed write never leaves a half-written file behind.
#ifndef RCM_IO_ATOMIC_FILE_H_
#define RCM_IO_ATOMIC_FILE_H_

#include <string>

#include "rcm/util/status.h"

namespace rcm {

// Reads a whole file. Errors: "PATH: cannot open: <reason>", "PATH: is a
// directory", read failure.
StatusOr<std::string> ReadFileToString(const std::string& path);

// Writes `contents` to a temporary file next to `path` and renames it over
// `path`, so that readers see either the old or the new file, never a part.
// On failure the temporary file is removed and `path` is left untouched.
Status WriteFileAtomically(const std::string& path,
                           const std::string& contents);

}  // namespace rcm

#endif  // RCM_IO_ATOMIC_FILE_H_
