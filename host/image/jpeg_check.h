// Whether a JPEG is whole. libjpeg reads a JPEG cut short as its image with the missing rows
// grey and says so only as a warning (JWRN_JPEG_EOF), which OpenImageIO does not pass on: a
// texture cut at half its data rendered grey with exit 0. A whole JPEG has an end-of-image marker
// (FF D9) after the start of its first scan (FF DA); entropy-coded data cannot hold one (a FF
// byte there is followed by 00 or a restart marker), and a thumbnail's EOI lies before the scan.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>

namespace spw {

// Reads up to `n` bytes at `offset` into `out`; returns how many it read.
using ReadAt = std::function<size_t(void* out, size_t n, std::uint64_t offset)>;

// "" if the `size` bytes `read` gives are not a JPEG, or a JPEG with its end-of-image marker
// after its first scan (or one whose markers this walk cannot follow: OpenImageIO judges it);
// else why not, naming `name` (as the message's subject: "'file.jpg'", "the embedded image"). Reads
// the markers before the first scan and the file backwards from its end to the marker (one read for
// a whole file).
std::string jpegCutShort(const ReadAt& read, std::uint64_t size, const std::string& name);

// The same for the file at `path`, named "'path'" ("" where it cannot be opened: its reader
// says why).
std::string jpegFileCutShort(const std::string& path);

} // namespace spw
