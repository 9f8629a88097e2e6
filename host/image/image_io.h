// Images in and out through OpenImageIO: linear float EXR, or 8-bit sRGB PNG, by extension.
#pragma once

#include <cmath>
#include <cstdint>
#include <functional>
#include <new>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace spw {

struct ImageRGB {
    int width = 0, height = 0;
    std::vector<float> rgb; // linear, row-major, 3 floats a pixel
};

// The sRGB transfer function, decoded: 8-bit images and textures are linearised with it.
inline float srgbToLinear(float c) {
    return c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f);
}

// A linear value as 8-bit sRGB, as PNG output and the preview window write it (NaN and
// negatives black, above 1 white).
std::uint8_t linearToSrgb8(float v);

// True for the extensions writeImage understands (.exr, .png; any case).
bool isSupportedOutput(const std::string& path);
// True for a path whose file name is a name followed by .exr, in any case ("a.EXR"; not ".exr",
// which names a hidden file without an extension).
bool isExrPath(const std::string& path);
// The file's bytes, in the format the path's extension names (.exr float, .png 8-bit sRGB).
std::vector<unsigned char> encodeImage(const std::string& path, const ImageRGB& image);
class OutputFile;
// Rows y0 .. y1 - 1 of an image, RGB floats, into `rgb` (width x (y1 - y0) x 3).
using ImageRows = std::function<void(int y0, int y1, float* rgb)>;
// Encodes a width x height image, a block of rows at a time, into `file` (not committed) in the
// format `path`'s extension names: a 16-Mpixel render needs neither its whole float image nor
// its encoded bytes in memory at once. `extra`: channels after R, G and B (an EXR's only), named
// so; `rows` then writes 3 + extra.size() floats a pixel. `attributes`: header entries (name,
// text) the file carries. Throws std::runtime_error naming the path.
void writeImageRows(OutputFile& file, const std::string& path, int width, int height,
                    const ImageRows& rows, const std::vector<std::string>& extra = {},
                    const std::vector<std::pair<std::string, std::string>>& attributes = {});
// Writes the image whole or not at all (host/image/output_file.h). Throws std::runtime_error naming
// the path when the file cannot be written.
void writeImage(const std::string& path, const ImageRGB& image);
// An 8-bit sRGB RGB image (compare's heatmap) with a description in its metadata, written the same
// way.
void writeImage8(const std::string& path, int width, int height, const unsigned char* rgb,
                 const std::string& software, const std::string& description);
// The most pixels an image Spillway renders, reads (a reference, a checkpoint, an environment
// map) or compares may have: 2^26 keeps film and ray ids well inside 32-bit indices.
constexpr long long kMaxImagePixels = 1LL << 26;
// EXR images up to this many pixels are zip-compressed (OpenEXR's default), larger ones RLE
// (encodeImage says why).
constexpr long long kZipImagePixels = 1LL << 22;

// Whether a header's size is one Spillway reads: 1 .. maxPixels pixels (a power of two), each
// side at most maxSide. "" if so, else why not, naming `path` (checked before any pixel is
// allocated: a header is a few bytes that may claim gigabytes). Textures read tile by tile have
// limits of their own (host/scene/scene.h, kMaxTexturePixels).
std::string imageSizeProblem(const std::string& path, long long width, long long height,
                             long long maxPixels = kMaxImagePixels,
                             long long maxSide = kMaxImagePixels);

// The message of a pixel buffer that cannot be allocated: "not enough memory for image 'PATH' (W x
// H): it needs N GiB, more than this process may take".
std::string outOfMemory(const std::string& path, long long width, long long height,
                        std::uint64_t bytes);

// `count` values of T for the pixels of image `path` (width x height), zeroed; where the process
// may not take that much memory (a std::bad_alloc), throws std::runtime_error saying so with the
// image, its size and the memory it needs, a runtime failure rather than the image's.
template <class T>
std::vector<T> pixelBuffer(size_t count, const std::string& path, long long width,
                           long long height) {
    try {
        return std::vector<T>(count);
    } catch (const std::bad_alloc&) {
        throw std::runtime_error(outOfMemory(path, width, height, count * sizeof(T)));
    }
}
// Whether an OpenEXR file's header can be handed to OpenEXR: "" if so (or if the file is not an
// EXR), else why not, naming `path`. OpenEXR allocates what a header claims before reading it: an
// attribute's size, the data window's offset table. A 200-byte file can claim gigabytes (found
// by fuzzing: 12 s of allocation per file). Checked here: every attribute lies within the file,
// and every part's data window is within kMaxImagePixels.
std::string exrHeaderProblem(const std::string& path);

// Reads any image OpenImageIO reads (its first three channels, or its one); 8-bit sRGB data are
// linearised. Throws on failure, and on a header larger than kMaxImagePixels before reading it.
ImageRGB readImage(const std::string& path);
// Reads layer `layer` of an EXR (a render pass: "Denoising Albedo"'s R, G and B, "Normal"'s X,
// Y and Z, "Depth"'s Z as grey), its channels named as Spillway writes them or under a view
// layer's name as Blender does ("ViewLayer.Denoising Albedo.R"), as stored (linear). Throws
// naming the path where the file has no such layer.
ImageRGB readImageLayer(const std::string& path, const std::string& layer);

} // namespace spw
