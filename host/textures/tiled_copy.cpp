#include "host/textures/tiled_copy.h"

#include "host/image/image_io.h"
#include "host/image/scratch_file.h"

#include <OpenImageIO/typedesc.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <memory>
#include <stdexcept>
#include <unistd.h>
#include <vector>

namespace spw {

namespace {

constexpr int kTile = 64;

// The inverse of srgbToLinear (image/image_io.h), which lookups decode with.
float srgbEncode(float c) {
    c = std::clamp(c, 0.0f, 1.0f);
    return c <= 0.0031308f ? c * 12.92f : 1.055f * std::pow(c, 1.0f / 2.4f) - 0.055f;
}

// Whether channel c of n is colour (sRGB-encoded where the image is): all but the alpha of grey
// and alpha (2 channels) or RGBA (4 and more: the fourth).
bool colourChannel(int c, int n) {
    return n == 2 ? c == 0 : c != 3;
}

// The rows [y0, y1) of a level of height h that make row y of the next one, of height hh: a
// pair, the last pair taking an odd last row too.
void sourceRows(int y, int h, int hh, int& y0, int& y1) {
    y0 = std::min(2 * y, h - 1);
    y1 = y + 1 == hh ? h : std::min(2 * y + 2, h);
}

// One row of the next MIP level (hw texels of n channels) from `rows`, the `count` rows of a
// level w texels wide that make it: averages of 2 x 2 texels, an odd last column averaged into
// the pair before it.
void halveRow(const float* rows, int w, int n, int count, int hw, float* out) {
    for (int x = 0; x < hw; ++x) {
        const int x0 = std::min(2 * x, w - 1), x1 = x + 1 == hw ? w : std::min(2 * x + 2, w);
        const float weight = 1.0f / float((x1 - x0) * count);
        for (int c = 0; c < n; ++c) {
            float sum = 0.0f;
            for (int yy = 0; yy < count; ++yy)
                for (int xx = x0; xx < x1; ++xx)
                    sum += rows[(size_t(yy) * size_t(w) + size_t(xx)) * size_t(n) + size_t(c)];
            out[size_t(x) * size_t(n) + size_t(c)] = sum * weight;
        }
    }
}

// The next MIP level of a w x h level of n channels (hw x hh), its rows in parallel.
std::vector<float> halve(const std::vector<float>& in, int w, int h, int n, int& hw, int& hh) {
    hw = std::max(1, w / 2);
    hh = std::max(1, h / 2);
    std::vector<float> out(size_t(hw) * size_t(hh) * size_t(n));
    const size_t row = size_t(w) * size_t(n);
    tbb::parallel_for(0, hh, [&](int y) {
        int y0, y1;
        sourceRows(y, h, hh, y0, y1);
        halveRow(in.data() + size_t(y0) * row, w, n, y1 - y0, hw,
                 out.data() + size_t(y) * size_t(hw) * size_t(n));
    });
    return out;
}

} // namespace

bool needsTiledCopy(const OIIO::ImageSpec& spec, int levels) {
    const bool oneTile =
        spec.tile_width == 0 || (spec.tile_width >= spec.width && spec.tile_height >= spec.height);
    return oneTile && levels == 1 && spec.x == 0 && spec.y == 0 && spec.depth == 1 &&
           spec.image_bytes() > kTiledCopyMinBytes;
}

namespace {

// How a level's texels are decoded and encoded: which channels are sRGB colour, and the 8-bit
// decoding table lookups use.
struct Encoding {
    const OIIO::ImageSpec& spec;
    std::vector<unsigned char> colour; // channel c is sRGB-encoded colour
    float table[2][256];
    Encoding(const OIIO::ImageSpec& s, bool srgb) : spec(s), colour(size_t(s.nchannels), 0) {
        for (int c = 0; c < s.nchannels; ++c)
            colour[size_t(c)] = srgb && colourChannel(c, s.nchannels);
        for (int i = 0; i < 256; ++i)
            table[0][i] = float(i) / 255.0f, table[1][i] = srgbToLinear(float(i) / 255.0f);
    }
    // `count` texel values in the image's format into linear floats; false if OpenImageIO
    // cannot convert the format.
    bool decode(const unsigned char* src, size_t count, float* out) const {
        const size_t n = colour.size();
        if (spec.format == OIIO::TypeDesc::UINT8) {
            for (size_t i = 0; i < count; i += n)
                for (size_t c = 0; c < n; ++c)
                    out[i + c] = table[colour[c]][src[i + c]];
            return true;
        }
        if (!OIIO::convert_pixel_values(spec.format, src, OIIO::TypeFloat, out, int(count)))
            return false;
        for (size_t i = 0; i < count; ++i)
            if (colour[i % n]) out[i] = srgbToLinear(out[i]);
        return true;
    }
    // A level in linear light, encoded as the image is (the writer quantises it to the format).
    std::vector<float> encode(std::vector<float> v) const {
        const size_t n = colour.size();
        tbb::parallel_for(size_t(0), v.size() / n, [&](size_t i) {
            for (size_t c = 0; c < n; ++c)
                if (colour[c]) v[i * n + c] = srgbEncode(v[i * n + c]);
        });
        return v;
    }
};

// Level 1 (w/2 x h/2) from the finest level in the image's format, each row from its source
// rows decoded there and then, so that no float copy of the finest level is ever held. Throws
// where the format cannot be converted.
std::vector<float> firstCoarseLevel(const std::vector<unsigned char>& finest, const Encoding& e,
                                    const std::string& name) {
    const int w = e.spec.width, h = e.spec.height, n = e.spec.nchannels;
    const int lw = std::max(1, w / 2), lh = std::max(1, h / 2);
    const size_t rowValues = size_t(w) * size_t(n), rowBytes = rowValues * e.spec.format.size();
    std::vector<float> level(size_t(lw) * size_t(lh) * size_t(n));
    std::atomic<bool> converted{true};
    tbb::parallel_for(0, lh, [&](int y) {
        int y0, y1;
        sourceRows(y, h, lh, y0, y1);
        const size_t count = size_t(y1 - y0) * rowValues;
        thread_local std::vector<float> rows;
        rows.resize(count);
        if (!e.decode(finest.data() + size_t(y0) * rowBytes, count, rows.data())) converted = false;
        halveRow(rows.data(), w, n, y1 - y0, lw, level.data() + size_t(y) * size_t(lw) * size_t(n));
    });
    if (!converted) throw std::runtime_error("cannot convert texture '" + name + "' to tile it");
    return level;
}

} // namespace

std::vector<unsigned char> TiledCopy::readFinest(const std::string& name,
                                                 const OIIO::ImageSpec* config,
                                                 const OIIO::ImageSpec& spec) {
    std::vector<unsigned char> finest(spec.image_bytes());
    auto in = OIIO::ImageInput::open(name, config);
    if (!in || !in->read_image(0, 0, 0, spec.nchannels, spec.format, finest.data()))
        throw ReadError(in ? in->geterror() : OIIO::geterror());
    return finest;
}

TiledCopy::TiledCopy(const std::string& name, const OIIO::ImageSpec* config,
                     const OIIO::ImageSpec& spec, bool srgb, const std::string& folder) {
    std::vector<unsigned char> finest = readFinest(name, config, spec);
    fd_ = openScratchFile(folder, "texture tile");
    path_ = "/proc/self/fd/" + std::to_string(fd_);
    // Its levels take a third more than the finest alone; a folder without the room is said
    // to be full, before a tile is written and after one fails (another process may fill it).
    const std::uint64_t needed = spec.image_bytes() / 3 * 4 + (std::uint64_t(1) << 16);
    if (std::string full = fullFolder(folder, needed, "copy"); !full.empty())
        throw std::runtime_error(full);
    auto out = OIIO::ImageOutput::create("tiff");
    if (!out) throw std::runtime_error("cannot write tiled textures: " + OIIO::geterror());
    auto fail = [&] {
        std::string why = fullFolder(folder, needed - std::min<std::uint64_t>(needed, bytes_),
                                     "rest of the copy");
        if (why.empty()) { // OpenImageIO's first line (it says one per tile)
            why = out->geterror();
            why = "in '" + folder + "': " + why.substr(0, why.find('\n'));
        }
        return std::runtime_error(why);
    };
    auto levelSpec = [&](int lw, int lh) {
        OIIO::ImageSpec s(lw, lh, spec.nchannels, spec.format);
        s.tile_width = s.tile_height = kTile;
        s.attribute("compression", "none");
        // What makes the TIFF reader take the subimages for MIP levels.
        s.attribute("textureformat", "Plain Texture");
        return s;
    };
    if (!out->open(path_, levelSpec(spec.width, spec.height), OIIO::ImageOutput::Create) ||
        !out->write_image(spec.format, finest.data()))
        throw fail();
    bytes_ = finest.size();
    if (spec.width == 1 && spec.height == 1) {
        if (!out->close()) throw fail();
        return;
    }
    // The coarser levels, in float and linear light.
    const Encoding encoding(spec, srgb);
    std::vector<float> level = firstCoarseLevel(finest, encoding, name);
    std::vector<unsigned char>().swap(finest); // freed: the coarser levels come from level 1
    int lw = std::max(1, spec.width / 2), lh = std::max(1, spec.height / 2);
    for (;;) {
        const OIIO::ImageSpec s = levelSpec(lw, lh);
        if (!out->open(path_, s, OIIO::ImageOutput::AppendSubimage) ||
            !out->write_image(OIIO::TypeFloat, encoding.encode(level).data()))
            throw fail();
        bytes_ += s.image_bytes();
        if (lw == 1 && lh == 1) break;
        int hw, hh;
        level = halve(level, lw, lh, spec.nchannels, hw, hh);
        lw = hw, lh = hh;
    }
    if (!out->close()) throw fail();
}

TiledCopy::~TiledCopy() {
    if (fd_ >= 0) ::close(fd_);
}

} // namespace spw
