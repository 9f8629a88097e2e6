#include "host/image/jpeg_check.h"

#include <algorithm>
#include <fstream>
#include <vector>

namespace spw {

std::string jpegCutShort(const ReadAt& read, std::uint64_t size, const std::string& name) {
    unsigned char b[4] = {};
    if (size < 4 || read(b, 2, 0) != 2 || b[0] != 0xFF || b[1] != 0xD8) return ""; // not a JPEG
    // The segments before the first scan, each marker's length read to step over it.
    std::uint64_t at = 2, scan = 0;
    while (at + 4 <= size && read(b, 4, at) == 4 && b[0] == 0xFF) {
        if (b[1] == 0xDA) {
            scan = at;
            break;
        }
        if (b[1] == 0xFF) { // fill bytes before a marker
            ++at;
            continue;
        }
        const bool standalone = b[1] == 0x01 || (b[1] >= 0xD0 && b[1] <= 0xD7);
        at += standalone ? 2 : 2 + (std::uint64_t(b[2]) << 8 | b[3]);
    }
    const std::string cut = name + " is a JPEG cut short: it has no end-of-image marker after " +
                            "its image data (a truncated or damaged file)";
    if (scan == 0) return at + 4 > size ? cut : ""; // the file ends before a scan; else not ours
    // Its end-of-image marker, searched from the end back to the scan.
    std::vector<unsigned char> chunk(std::size_t(1) << 16);
    for (std::uint64_t end = size; end > scan + 2;) {
        const std::uint64_t start =
            std::max<std::uint64_t>(scan + 2, end > chunk.size() ? end - chunk.size() : 0);
        const size_t n = read(chunk.data(), size_t(end - start), start);
        if (n != end - start) return "";
        for (size_t i = n; i-- > 1;)
            if (chunk[i - 1] == 0xFF && chunk[i] == 0xD9) return "";
        end = start + 1; // a marker may straddle two chunks
        if (start == scan + 2) break;
    }
    return cut;
}

std::string jpegFileCutShort(const std::string& path) {
    std::ifstream in(path, std::ios::binary | std::ios::ate);
    if (!in) return "";
    const std::uint64_t size = std::uint64_t(in.tellg());
    return jpegCutShort(
        [&](void* out, size_t n, std::uint64_t offset) {
            in.clear();
            in.seekg(std::streamoff(offset));
            in.read(static_cast<char*>(out), std::streamsize(n));
            return size_t(in.gcount());
        },
        size, "'" + path + "'");
}

} // namespace spw
