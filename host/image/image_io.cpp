#include "host/image/image_io.h"

#include "host/image/output_file.h"

#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>

namespace spw {
namespace {

std::string extension(const std::string& path) {
    std::string e = std::filesystem::path(path).extension().string();
    std::transform(e.begin(), e.end(), e.begin(),
                   [](unsigned char c) { return char(std::tolower(c)); });
    return e;
}

} // namespace

std::string outOfMemory(const std::string& path, long long width, long long height,
                        std::uint64_t bytes) {
    char need[32];
    std::snprintf(need, sizeof need, "%.1f GiB", double(bytes) / double(1ull << 30));
    return "not enough memory for image '" + path + "' (" + std::to_string(width) + " x " +
           std::to_string(height) + "): it needs " + need + ", more than this process may take";
}

std::uint8_t linearToSrgb8(float v) {
    if (!(v > 0.0f)) return 0; // also maps NaN to black
    float s = v <= 0.0031308f ? 12.92f * v : 1.055f * std::pow(v, 1.0f / 2.4f) - 0.055f;
    return std::uint8_t(std::lround(std::clamp(s, 0.0f, 1.0f) * 255.0f));
}

bool isSupportedOutput(const std::string& path) {
    std::string e = extension(path);
    return e == ".exr" || e == ".png";
}

bool isExrPath(const std::string& path) {
    return extension(path) == ".exr";
}

namespace {

// Encodes through OpenImageIO into memory (the format by the path's extension): OpenImageIO
// never touches the destination, so a failure leaves no file.
std::vector<unsigned char> encode(const std::string& path, const OIIO::ImageSpec& spec,
                                  OIIO::TypeDesc format, const void* data) {
    std::vector<unsigned char> bytes;
    // Room for the pixels uncompressed and a header: the buffer is never copied as it grows.
    bytes.reserve(spec.image_bytes() + 65536);
    OIIO::Filesystem::IOVecOutput proxy(bytes);
    auto out = OIIO::ImageOutput::create(path, &proxy);
    if (!out) throw std::runtime_error("cannot write '" + path + "': " + OIIO::geterror());
    bool ok = out->open(path, spec) && out->write_image(format, data);
    std::string err = ok ? "" : out->geterror();
    if (!out->close() && ok) err = out->geterror(), ok = false;
    if (!ok) throw std::runtime_error("cannot write '" + path + "': " + err);
    return bytes;
}

} // namespace

namespace {

// The spec Spillway writes `path` with: linear float EXR or 8-bit sRGB PNG; an EXR with `extra`
// channels after R, G and B.
OIIO::ImageSpec outputSpec(const std::string& path, int width, int height,
                           const std::vector<std::string>& extra = {}) {
    if (!isSupportedOutput(path))
        throw std::runtime_error("cannot write '" + path + "': use .exr or .png");
    const bool png = extension(path) == ".png";
    if (png && !extra.empty())
        throw std::runtime_error("cannot write '" + path + "': only an EXR holds more channels");
    OIIO::ImageSpec spec(width, height, 3 + int(extra.size()),
                         png ? OIIO::TypeDesc::UINT8 : OIIO::TypeDesc::FLOAT);
    if (!extra.empty()) {
        spec.channelnames = {"R", "G", "B"};
        spec.channelnames.insert(spec.channelnames.end(), extra.begin(), extra.end());
    }
    spec.attribute("oiio:ColorSpace", png ? "sRGB" : "Linear");
    spec.attribute("Software", "Spillway");
    // OpenEXR's default, zip, packs a rendered float image 5 % smaller than RLE, at 3x the time:
    // 3.9 s against 1.3 s for 16 Mpixels on 2 threads (a render's mantissas are noise to a
    // compressor). Large images are written with RLE, which still packs black and flat regions.
    if (!png && std::int64_t(width) * height > kZipImagePixels)
        spec.attribute("compression", "rle");
    return spec;
}

std::vector<std::uint8_t> toSrgb8(const float* rgb, size_t values) {
    std::vector<std::uint8_t> bytes(values);
    std::transform(rgb, rgb + values, bytes.begin(), linearToSrgb8);
    return bytes;
}

// OpenImageIO's writers write through this into an OutputFile, at the offsets they ask for
// (OpenEXR goes back to fill in its chunk table). An error is kept and reported as a short
// write, which the writer turns into its own failure; writeImageRows then throws the kept one.
class OutputFileProxy : public OIIO::Filesystem::IOProxy {
  public:
    explicit OutputFileProxy(OutputFile& file) : IOProxy("", Write), file_(file) {}
    const char* proxytype() const override { return "spillway-output"; }
    size_t write(const void* buf, size_t size) override {
        const size_t n = pwrite(buf, size, m_pos);
        m_pos += int64_t(n);
        return n;
    }
    size_t pwrite(const void* buf, size_t size, int64_t offset) override {
        if (!failure_.empty()) return 0;
        try {
            file_.writeAt(std::uint64_t(offset), buf, size);
        } catch (const std::exception& e) {
            failure_ = e.what();
            return 0;
        }
        size_ = std::max(size_, size_t(offset) + size);
        return size;
    }
    size_t size() const override { return size_; }
    const std::string& failure() const { return failure_; }

  private:
    OutputFile& file_;
    size_t size_ = 0;
    std::string failure_;
};

} // namespace

std::vector<unsigned char> encodeImage(const std::string& path, const ImageRGB& image) {
    const OIIO::ImageSpec spec = outputSpec(path, image.width, image.height);
    if (spec.format == OIIO::TypeDesc::UINT8) {
        const std::vector<std::uint8_t> bytes = toSrgb8(image.rgb.data(), image.rgb.size());
        return encode(path, spec, OIIO::TypeDesc::UINT8, bytes.data());
    }
    return encode(path, spec, OIIO::TypeDesc::FLOAT, image.rgb.data());
}

void writeImageRows(OutputFile& file, const std::string& path, int width, int height,
                    const ImageRows& rows, const std::vector<std::string>& extra,
                    const std::vector<std::pair<std::string, std::string>>& attributes) {
    OIIO::ImageSpec spec = outputSpec(path, width, height, extra);
    for (const auto& [name, value] : attributes)
        spec.attribute(name, value);
    const size_t channels = size_t(spec.nchannels);
    if (!file.seekable()) { // a FIFO: encoded in memory, then written in order
        std::vector<float> all(size_t(width) * size_t(height) * channels);
        rows(0, height, all.data());
        const std::vector<unsigned char> bytes =
            spec.format == OIIO::TypeDesc::UINT8
                ? encode(path, spec, OIIO::TypeDesc::UINT8, toSrgb8(all.data(), all.size()).data())
                : encode(path, spec, OIIO::TypeDesc::FLOAT, all.data());
        file.write(bytes.data(), bytes.size());
        return;
    }
    OutputFileProxy proxy(file);
    auto out = OIIO::ImageOutput::create(path, &proxy);
    if (!out) throw std::runtime_error("cannot write '" + path + "': " + OIIO::geterror());
    // Blocks of about 4 MiB of floats: enough lines for every thread of the EXR writer.
    const int block =
        std::min(height, std::max(16, int((size_t(4) << 20) / (size_t(width) * 4 * channels))));
    std::vector<float> rgb(size_t(width) * size_t(block) * channels);
    bool ok = out->open(path, spec);
    for (int y0 = 0; ok && y0 < height; y0 += block) {
        const int y1 = std::min(height, y0 + block);
        rows(y0, y1, rgb.data());
        const size_t values = size_t(width) * size_t(y1 - y0) * channels;
        ok = spec.format == OIIO::TypeDesc::UINT8
                 ? out->write_scanlines(y0, y1, 0, OIIO::TypeDesc::UINT8,
                                        toSrgb8(rgb.data(), values).data())
                 : out->write_scanlines(y0, y1, 0, OIIO::TypeDesc::FLOAT, rgb.data());
    }
    std::string err = ok ? "" : out->geterror();
    if (!out->close() && ok) err = out->geterror(), ok = false;
    if (!proxy.failure().empty()) throw std::runtime_error(proxy.failure());
    if (!ok) throw std::runtime_error("cannot write '" + path + "': " + err);
}

void writeImage(const std::string& path, const ImageRGB& image) {
    const std::vector<unsigned char> bytes = encodeImage(path, image);
    writeFileAtomically(path, bytes.data(), bytes.size());
}

void writeImage8(const std::string& path, int width, int height, const unsigned char* rgb,
                 const std::string& software, const std::string& description) {
    OIIO::ImageSpec spec(width, height, 3, OIIO::TypeDesc::UINT8);
    spec.attribute("oiio:ColorSpace", "sRGB");
    spec.attribute("Software", software);
    spec.attribute("ImageDescription", description);
    const std::vector<unsigned char> bytes = encode(path, spec, OIIO::TypeDesc::UINT8, rgb);
    writeFileAtomically(path, bytes.data(), bytes.size());
}

std::string imageSizeProblem(const std::string& path, long long width, long long height,
                             long long maxPixels, long long maxSide) {
    if (width >= 1 && height >= 1 && width <= maxSide && height <= maxSide &&
        width <= maxPixels / height)
        return "";
    std::string limit =
        "1 to 2^" + std::to_string(63 - __builtin_clzll(std::uint64_t(maxPixels))) + " pixels";
    if (maxSide < maxPixels) limit += ", sides up to " + std::to_string(maxSide);
    return "image '" + path + "' is " + std::to_string(width) + " x " + std::to_string(height) +
           " pixels; Spillway reads images of " + limit;
}

namespace {

// What one EXR part's header says about its layout, as far as memory goes.
struct ExrLayout {
    long long width = 0, height = 0; // the data window; 0: none given
    long long bytesPerPixel = 0;     // over the channel list
    long long linesPerChunk = 1;     // from the compression
    long long tileWidth = 0, tileHeight = 0;

    // Why a file of `fileSize` bytes cannot hold this layout, or "". Its chunk offset table is
    // in the file (8 bytes a chunk), and no codec OpenEXR has packs a chunk more than 4096 : 1
    // (deflate's limit is 1032 : 1): OpenEXR sizes both its offset table and its chunk buffers
    // from the header before reading any pixel.
    std::string problem(std::uint64_t fileSize) const {
        if (width <= 0 || height <= 0) return "";
        const bool tiled = tileWidth > 0 && tileHeight > 0;
        const long long chunks =
            tiled ? ((width + tileWidth - 1) / tileWidth) * ((height + tileHeight - 1) / tileHeight)
                  : (height + linesPerChunk - 1) / linesPerChunk;
        const double chunkBytes = double(bytesPerPixel) * (tiled ? double(tileWidth) * tileHeight
                                                                 : double(width) * linesPerChunk);
        if (double(chunks) * 8.0 > double(fileSize))
            return "its header claims " + std::to_string(chunks) + " chunks, more than its " +
                   std::to_string(fileSize) + " bytes hold";
        if (chunkBytes > 4096.0 * double(fileSize))
            return "its header claims chunks of " + std::to_string((long long)chunkBytes) +
                   " bytes, more than its " + std::to_string(fileSize) + " bytes could unpack to";
        return "";
    }
};

std::int32_t littleEndian32(const unsigned char* b) {
    return std::int32_t(std::uint32_t(b[0]) | std::uint32_t(b[1]) << 8 | std::uint32_t(b[2]) << 16 |
                        std::uint32_t(b[3]) << 24);
}

// OpenEXR reads the attribute types it knows by their own size, not the size the header gives
// (and a channel list up to its terminator): where the two differ, OpenEXR parses the rest of the
// header from another place than this check does. So a known type's value must be exactly its
// size. (A fuzzer's file did this: a channel list that ended early, then an attribute of 1.7 GB
// that only OpenEXR saw.)
std::string sizeProblem(const std::string& type, const std::vector<unsigned char>& v) {
    static const std::pair<const char*, size_t> kFixed[] = {{"box2i", 16},
                                                            {"box2f", 16},
                                                            {"int", 4},
                                                            {"float", 4},
                                                            {"double", 8},
                                                            {"v2i", 8},
                                                            {"v2f", 8},
                                                            {"v2d", 16},
                                                            {"v3i", 12},
                                                            {"v3f", 12},
                                                            {"v3d", 24},
                                                            {"m33f", 36},
                                                            {"m33d", 72},
                                                            {"m44f", 64},
                                                            {"m44d", 128},
                                                            {"compression", 1},
                                                            {"lineOrder", 1},
                                                            {"envmap", 1},
                                                            {"deepImageState", 1},
                                                            {"tiledesc", 9},
                                                            {"chromaticities", 32},
                                                            {"keycode", 28},
                                                            {"timecode", 8},
                                                            {"rational", 8}};
    for (const auto& [name, size] : kFixed)
        if (type == name && v.size() != size) return "an attribute of type " + type + " is damaged";
    if (type == "stringvector") { // each string's length, then the string: within the value
        for (size_t i = 0; i < v.size();) {
            if (i + 4 > v.size()) return "an attribute of type stringvector is damaged";
            const std::uint64_t length = std::uint32_t(littleEndian32(&v[i]));
            if (i + 4 + length > v.size()) return "an attribute of type stringvector is damaged";
            i += 4 + size_t(length);
        }
    }
    if (type == "preview") {
        const std::uint64_t w = v.size() >= 8 ? std::uint32_t(littleEndian32(&v[0])) : 0,
                            h = v.size() >= 8 ? std::uint32_t(littleEndian32(&v[4])) : 0;
        const bool fits = w == 0 || h <= v.size() / 4 / w; // and w * h cannot wrap
        if (v.size() < 8 || !fits || 8 + 4 * w * h != v.size())
            return "its preview image is damaged";
    }
    return "";
}

// Reads what ExrLayout needs from one attribute's value; returns why the value is damaged, or "".
std::string noteAttribute(ExrLayout& layout, const std::string& name, const std::string& type,
                          const std::vector<unsigned char>& v) {
    if (const std::string why = sizeProblem(type, v); !why.empty()) return why;
    if (name == "dataWindow" && type == "box2i" && v.size() == 16) {
        layout.width = (long long)littleEndian32(&v[8]) - littleEndian32(&v[0]) + 1;
        layout.height = (long long)littleEndian32(&v[12]) - littleEndian32(&v[4]) + 1;
    } else if (name == "compression" && type == "compression" && v.size() == 1) {
        constexpr int kLines[] = {1, 1, 1, 16, 32, 16, 32, 32, 32, 256}; // none .. dwab
        layout.linesPerChunk = v[0] < 10 ? kLines[v[0]] : 256;
    } else if (name == "tiles" && type == "tiledesc" && v.size() >= 8) {
        layout.tileWidth = std::uint32_t(littleEndian32(&v[0]));
        layout.tileHeight = std::uint32_t(littleEndian32(&v[4]));
    } else if (type == "chlist") { // any of them: OpenEXR parses each to its terminator
        // Entries of name\0, pixel type (0 uint, 1 half, 2 float), linear, 3 reserved, x and y
        // sampling; an empty name ends the list, within the attribute.
        size_t i = 0;
        while (i < v.size() && v[i] != 0) {
            const size_t start = i;
            while (i < v.size() && v[i] != 0)
                ++i;
            if (i - start > 255 || i + 17 > v.size()) return "its channel list is damaged";
            const std::int32_t pixelType = littleEndian32(&v[i + 1]);
            if (pixelType < 0 || pixelType > 2 || littleEndian32(&v[i + 9]) < 1 ||
                littleEndian32(&v[i + 13]) < 1)
                return "its channel list is damaged";
            if (name == "channels") layout.bytesPerPixel += pixelType == 1 ? 2 : 4;
            i += 17;
        }
        if (i + 1 != v.size()) return "its channel list is damaged"; // its terminator ends it
    }
    return "";
}

} // namespace

std::string exrHeaderProblem(const std::string& path) {
    std::ifstream in(path, std::ios::binary | std::ios::ate);
    if (!in) return ""; // the reader says why it cannot open it
    const std::uint64_t fileSize = std::uint64_t(in.tellg());
    in.seekg(0);
    unsigned char head[8] = {};
    if (!in.read(reinterpret_cast<char*>(head), 8) || head[0] != 0x76 || head[1] != 0x2f ||
        head[2] != 0x31 || head[3] != 0x01)
        return ""; // not an EXR: its own reader's checks apply
    const bool multipart = (head[5] & 0x10) != 0;
    auto damaged = [&](const std::string& why) {
        return "'" + path + "' is not an OpenEXR file Spillway reads: " + why;
    };
    auto readName = [&](std::string& name) {
        name.clear();
        for (char c; in.get(c);) {
            if (c == '\0') return true;
            if (name.size() >= 255) return false;
            name += c;
        }
        return false;
    };
    for (int part = 0;; ++part) {
        std::string name, type;
        if (!readName(name)) return damaged("its header ends early");
        if (name.empty()) {
            if (!multipart || part > 0) return ""; // the end of the (last) header
            return damaged("an empty header");
        }
        // One header's attributes, the first already named; an empty name ends it.
        ExrLayout layout;
        while (!name.empty()) {
            unsigned char size[4];
            if (!readName(type) || !in.read(reinterpret_cast<char*>(size), 4))
                return damaged("its header ends early");
            const std::uint32_t bytes = std::uint32_t(littleEndian32(size));
            if (std::uint64_t(in.tellg()) + bytes > fileSize)
                return damaged("attribute '" + name + "' claims " + std::to_string(bytes) +
                               " bytes, past the end of the file");
            std::vector<unsigned char> value(bytes);
            if (!in.read(reinterpret_cast<char*>(value.data()), std::streamsize(bytes)))
                return damaged("its header ends early");
            if (const std::string why = noteAttribute(layout, name, type, value); !why.empty())
                return damaged(why);
            if (!readName(name)) return damaged("its header ends early");
        }
        if (const std::string why = imageSizeProblem(path, layout.width, layout.height);
            layout.width != 0 && !why.empty())
            return why;
        if (const std::string why = layout.problem(fileSize); !why.empty()) return damaged(why);
        if (!multipart) return "";
    }
}

namespace {

// The image at `path` opened for reading, its header checked (a regular file, an EXR header
// that claims nothing past the file, a size within kMaxImagePixels, a channel at least).
std::unique_ptr<OIIO::ImageInput> openChecked(const std::string& path) {
    // A FIFO or a folder would block the open or read as nonsense: regular files only.
    std::error_code ec;
    if (!std::filesystem::is_regular_file(path, ec))
        throw std::runtime_error("image '" + path + "' is not a regular file");
    if (const std::string why = exrHeaderProblem(path); !why.empty()) throw std::runtime_error(why);
    // Colour as stored: not premultiplied by an alpha channel the reader would otherwise apply.
    OIIO::ImageSpec config;
    config.attribute("oiio:UnassociatedAlpha", 1);
    auto in = OIIO::ImageInput::open(path, &config);
    if (!in) throw std::runtime_error("cannot read image '" + path + "': " + OIIO::geterror());
    const OIIO::ImageSpec& spec = in->spec();
    if (const std::string why = imageSizeProblem(path, spec.width, spec.height); !why.empty())
        throw std::runtime_error(why);
    if (spec.nchannels < 1) throw std::runtime_error("image '" + path + "' has no channel");
    return in;
}

// The index of channel `layer`.`component` of `spec`, alone or under a view layer's name
// ("ViewLayer.Normal.X", as Blender writes it), or -1.
int layerChannel(const OIIO::ImageSpec& spec, const std::string& layer,
                 const std::string& component) {
    const std::string tail = layer + "." + component;
    for (int c = 0; c < spec.nchannels; ++c) {
        const std::string& n = spec.channelnames[size_t(c)];
        if (n == tail) return c;
        if (n.size() > tail.size() && n.compare(n.size() - tail.size(), tail.size(), tail) == 0 &&
            n[n.size() - tail.size() - 1] == '.')
            return c;
    }
    return -1;
}

} // namespace

ImageRGB readImageLayer(const std::string& path, const std::string& layer) {
    std::unique_ptr<OIIO::ImageInput> in = openChecked(path);
    const OIIO::ImageSpec& spec = in->spec();
    std::vector<int> picked;
    for (const std::vector<const char*>& set :
         std::vector<std::vector<const char*>>{{"R", "G", "B"}, {"X", "Y", "Z"}, {"Z"}, {"V"}}) {
        picked.clear();
        for (const char* component : set)
            if (const int c = layerChannel(spec, layer, component); c >= 0) picked.push_back(c);
        if (picked.size() == set.size()) break;
        picked.clear();
    }
    if (picked.empty())
        throw std::runtime_error("image '" + path + "' has no layer '" + layer + "' (channels " +
                                 layer + ".R, .G, .B or .X, .Y, .Z, or .Z)");
    const size_t pixels = size_t(spec.width) * size_t(spec.height);
    std::vector<float> all =
        pixelBuffer<float>(pixels * size_t(spec.nchannels), path, spec.width, spec.height);
    if (!in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, all.data()))
        throw std::runtime_error("cannot read image '" + path + "': " + in->geterror());
    ImageRGB img;
    img.width = spec.width;
    img.height = spec.height;
    img.rgb.resize(pixels * 3);
    for (size_t i = 0; i < pixels; ++i)
        for (size_t c = 0; c < 3; ++c)
            img.rgb[i * 3 + c] =
                all[i * size_t(spec.nchannels) + size_t(picked[std::min(c, picked.size() - 1)])];
    return img;
}

ImageRGB readImage(const std::string& path) {
    std::unique_ptr<OIIO::ImageInput> in = openChecked(path);
    const OIIO::ImageSpec& spec = in->spec();
    ImageRGB img;
    img.width = spec.width;
    img.height = spec.height;
    // RGB, or grey (grey and alpha: the grey); never the file's other channels.
    const int nc = spec.nchannels == 2 ? 1 : std::min(spec.nchannels, 3);
    const size_t pixels = size_t(spec.width) * size_t(spec.height);
    std::vector<float> all = pixelBuffer<float>(pixels * size_t(nc), path, spec.width, spec.height);
    if (!in->read_image(0, 0, 0, nc, OIIO::TypeDesc::FLOAT, all.data()))
        throw std::runtime_error("cannot read image '" + path + "': " + in->geterror());
    std::string cs = spec.get_string_attribute("oiio:ColorSpace");
    const bool srgb = cs == "sRGB" || (cs.empty() && spec.format == OIIO::TypeDesc::UINT8);
    img.rgb.resize(pixels * 3);
    for (size_t i = 0; i < pixels; ++i)
        for (int c = 0; c < 3; ++c) {
            float v = all[i * size_t(nc) + size_t(std::min(c, nc - 1))];
            img.rgb[i * 3 + size_t(c)] = srgb ? srgbToLinear(v) : v;
        }
    return img;
}

} // namespace spw
