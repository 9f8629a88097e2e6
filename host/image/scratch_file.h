// Unnamed files in the scratch folder: ray batches spilled past the memory budget
// (pipeline/spill_file.h) and tiled copies of large textures (textures/tiled_copy.h). Each is
// opened with O_TMPFILE (or created and unlinked at once where the file system lacks it), so it
// has no name from the start: whatever way the process ends, normal exit, exception, SIGINT,
// SIGTERM or SIGKILL, the kernel frees it and no file is left behind.
#pragma once

#include <cstdint>
#include <string>

namespace spw {

// The folder scratch files go to: `configured` (--spill-dir) if set, else $TMPDIR, $TMP, $TEMP or
// $TEMPDIR, else /tmp. It is not checked: that is the first scratch file's to report.
std::string scratchFolder(const std::string& configured);

// A new unnamed file in `dir`, open for reading and writing (close-on-exec). Throws
// std::runtime_error "cannot create a WHAT file in 'DIR': why".
int openScratchFile(const std::string& dir, const char* what);

// Where folder `dir` has fewer than `bytes` bytes free: "the scratch folder 'DIR' is full (F MiB
// free, the WHAT needs N MiB; --spill-dir chooses another)"; else "".
std::string fullFolder(const std::string& dir, std::uint64_t bytes, const char* what);

} // namespace spw
