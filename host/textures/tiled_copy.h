// Tiled, MIP-mapped copies of large untiled images. A PNG or JPEG is not tiled: OpenImageIO's
// cache holds it as one tile, the whole decoded image (200 MB for an 8192 x 8192 RGB image),
// which it can neither share with a budget smaller than that nor read a part of. An untiled
// image of one MIP level whose finest level decodes to more than kTiledCopyMinBytes is read
// once, when the scene's textures are opened, and written to an unnamed file in the scratch
// folder (image/scratch_file.h) as a TIFF of 64 x 64 tiles in the image's own pixel format,
// with its MIP levels down to 1 x 1; the cache then reads that file a tile at a time, within
// its budget. The finest level is the image's pixels, bit for bit. Each coarser level averages
// 2 x 2 texels of the one above (an odd last row or column joins the pair before it), sRGB
// colour channels in linear light and encoded back (alpha, and linear images, as they are).
// The decision depends on the image alone, never on the budget: a scene renders the same image
// under any --texture-cache.
#pragma once

#include <OpenImageIO/imageio.h>

#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

namespace spw {

// Images whose finest level decodes to more than this get a tiled copy (16 MiB: 2048 x 2048
// RGBA 8-bit is the largest that does not).
constexpr std::uint64_t kTiledCopyMinBytes = std::uint64_t(16) << 20;

// Whether an image whose first MIP level is `spec` (as the cache gives it: an untiled file
// as one tile of the whole image), of `levels` MIP levels, gets a tiled copy.
bool needsTiledCopy(const OIIO::ImageSpec& spec, int levels);

// The tiled copy of one image, alive as long as the file it names.
class TiledCopy {
  public:
    // The image's pixels could not be read (a truncated or corrupt file): what OpenImageIO said.
    struct ReadError : std::runtime_error {
        using std::runtime_error::runtime_error;
    };
    // Reads image `name` (through `config`, which may name an IOProxy; nullptr for none), whose
    // first level is `spec`, and writes its copy into a new unnamed file in `folder`. srgb: its
    // colour channels are sRGB-encoded (MIP levels are averaged in linear light). Throws
    // ReadError where the image's pixels cannot be read, std::runtime_error naming the folder
    // where the copy cannot be written.
    TiledCopy(const std::string& name, const OIIO::ImageSpec* config, const OIIO::ImageSpec& spec,
              bool srgb, const std::string& folder);
    ~TiledCopy();
    TiledCopy(const TiledCopy&) = delete;
    TiledCopy& operator=(const TiledCopy&) = delete;

    // The copy's path, for the cache to open (/proc/self/fd/N: the file has no name).
    const std::string& path() const { return path_; }
    std::uint64_t bytes() const { return bytes_; } // pixel bytes written, every level

  private:
    // The finest level in the image's own format, as the file holds it.
    static std::vector<unsigned char>
    readFinest(const std::string& name, const OIIO::ImageSpec* config, const OIIO::ImageSpec& spec);
    int fd_ = -1;
    std::string path_;
    std::uint64_t bytes_ = 0;
};

} // namespace spw
