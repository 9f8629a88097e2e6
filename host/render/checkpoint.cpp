#include "host/render/checkpoint.h"

#include "host/image/image_io.h"
#include "host/image/output_file.h"

#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <stdexcept>

namespace spw {
namespace {

constexpr int kSumsPerPixel = 8;
constexpr int kWordsPerSum = 4; // a 128-bit sum as four uint32 channels, most significant first
constexpr int kSamplesChannel = 3 + kWordsPerSum * kSumsPerPixel; // the pixel's sample count
constexpr int kChannels = kSamplesChannel + 1;                    // without fine levels
constexpr int kLevelSums = 6; // a fine level's sums a pixel: (r, g, b) x 2
constexpr int kLevelChannels = kLevelSums * kWordsPerSum;

// The channel of word w (0: the most significant) of sum k, of the home grid or of a fine level.
std::string sumChannel(int k, int w) {
    return "state." + std::to_string(k) + "." + std::to_string(w);
}
std::string levelChannel(int level, int k, int w) {
    return "state.fine" + std::to_string(level) + "." + std::to_string(k) + "." + std::to_string(w);
}

// The four uint32 words of a 128-bit sum, most significant first, and back.
void putWords(Film::Fixed v, std::uint32_t* out) {
    const auto bits = static_cast<unsigned __int128>(v);
    for (int w = 0; w < kWordsPerSum; ++w)
        out[w] = std::uint32_t(bits >> (32 * (kWordsPerSum - 1 - w)));
}

std::string fileText(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

const char* filterName(TextureFilter f) {
    return f == TextureFilter::Cone ? "cone" : "finest";
}

[[noreturn]] void notACheckpoint(const std::string& path, const std::string& why) {
    throw std::runtime_error("'" + path + "' is not a Spillway checkpoint: " + why);
}

// A double as text that reads back as the same double (17 significant digits).
std::string exactText(double v) {
    char text[32];
    std::snprintf(text, sizeof text, "%.17g", v);
    return text;
}

// A double as a message says it ("1e-12", "0.002").
std::string shortText(double v) {
    char text[32];
    std::snprintf(text, sizeof text, "%g", v);
    return text;
}

// A digest of everything a resume or a merge reads: the key, the progress and the film's exact
// state (not the RGB preview, which nothing reads back). Written as spillway:checksum; a file
// whose contents do not match it was damaged (a flipped bit near its end used to resume into an
// image relMSE 3059 away) or edited.
std::uint64_t checkpointChecksum(const Checkpoint& c) {
    Fnv f;
    const CheckpointKey& k = c.key;
    f.text(k.version);
    f.value(k.sceneHash).value(k.environmentHash).value(k.seed).value(k.width).value(k.height);
    f.value(k.sampleBase).value(k.strategy).value(k.adaptiveMinSamples);
    // The doubles as the file holds them (text), so that the reader's digest is the writer's.
    f.text(std::to_string(k.adaptiveThreshold));
    // Only where there is one: checkpoints without a target (all before it was kept) digest as
    // they always did.
    if (k.adaptiveTarget != 0) f.text(exactText(k.adaptiveTarget));
    f.text(std::to_string(c.renderSeconds));
    f.text(k.rayFormat);
    f.text(k.textureFilter);
    f.text(k.sampler);
    f.value(c.iterations).value(c.firstIteration).value(c.totalIterations);
    f.value(c.film.nonFinite).value(c.film.saturated);
    f.value(c.film.scaleExponent).value(c.film.weightExponent);
    f.array(c.film.sums);
    f.array(c.film.samples);
    // Only where the film has fine levels: checkpoints made before them digest as they did.
    if (c.film.levelBits != 0) f.value(c.film.levelBits);
    for (const Film::State::Level& l : c.film.levels)
        f.value(l.level).array(l.sums);
    return f.h;
}

// What a resume and a merge trust: progress within the render's own total, a sane time.
void checkProgress(const std::string& path, const Checkpoint& c) {
    const long long spi = (long long)c.key.sampleBase * c.key.sampleBase;
    if (c.key.sampleBase > 256 || c.totalIterations < 1 || spi * c.totalIterations > 0xFFFFFFFFLL)
        notACheckpoint(path, "its sample base " + std::to_string(c.key.sampleBase) + " and " +
                                 std::to_string(c.totalIterations) +
                                 " iterations are outside what a render takes");
    if (c.firstIteration >= c.totalIterations ||
        c.iterations > c.totalIterations - c.firstIteration)
        notACheckpoint(path, "it claims " + std::to_string(c.iterations) +
                                 " iterations from iteration " + std::to_string(c.firstIteration) +
                                 " of a render of " + std::to_string(c.totalIterations));
    if (!std::isfinite(c.renderSeconds) || c.renderSeconds < 0)
        notACheckpoint(path, "its render time is not a time");
}

} // namespace

void Fnv::bytes(const void* data, size_t n) {
    const auto* p = static_cast<const unsigned char*>(data);
    size_t i = 0;
    for (; i + 8 <= n; i += 8) { // a word at a time: meshes are large
        std::uint64_t w;
        std::memcpy(&w, p + i, 8);
        h = (h ^ w) * 0x100000001b3ull;
    }
    for (; i < n; ++i)
        h = (h ^ p[i]) * 0x100000001b3ull;
}

// Every byte of the file, read a MiB at a time (a multiple of Fnv's word). The path is not
// hashed: the same texels from another folder render the same image.
static void hashFileContents(Fnv& f, const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) {
        f.text("unreadable: " + path);
        return;
    }
    std::vector<char> chunk(size_t(1) << 20);
    std::uint64_t total = 0;
    while (in.read(chunk.data(), std::streamsize(chunk.size())) || in.gcount() > 0) {
        f.bytes(chunk.data(), size_t(in.gcount()));
        total += std::uint64_t(in.gcount());
    }
    f.value(total);
}

// The bytes of an embedded image, read from its file as the bytes that held them in memory were
// hashed (the same hash for the same bytes), a MiB at a time; a data: URI's as its base64 text.
static void hashEmbedded(Fnv& f, const EmbeddedImage& image) {
    if (image.bytes) {
        f.bytes(image.bytes->data(), image.bytes->size());
        return;
    }
    std::ifstream in(image.file, std::ios::binary);
    in.seekg(std::streamoff(image.offset));
    std::vector<char> chunk(size_t(1) << 20);
    for (std::uint64_t left = image.stored(); left > 0 && in;) {
        const size_t n = size_t(std::min<std::uint64_t>(left, chunk.size()));
        if (!in.read(chunk.data(), std::streamsize(n))) break;
        f.bytes(chunk.data(), n);
        left -= n;
    }
    if (!in) f.text("unreadable: " + image.file);
}

std::uint64_t environmentHash(const Scene& scene) {
    if (!scene.environment) return 0;
    const Environment& env = *scene.environment;
    Fnv f;
    f.value(env.radiance).value(env.width).value(env.height);
    f.array(env.rgb);
    return f.h;
}

std::uint64_t sceneHash(const Scene& scene) {
    Fnv f;
    f.text(fileText(scene.file));
    for (const std::string& input : scene.inputs)
        hashFileContents(f, input);
    for (const Mesh& m : scene.meshes) {
        f.array(m.positions);
        f.array(m.normals);
        f.array(m.uvs);
        if (!m.colours.empty()) f.array(m.colours);
        f.array(m.triangles);
    }
    for (const Instance& inst : scene.instances) // none: the hash as before instances were
        f.value(inst.prototype).value(inst.toWorld);
    for (const Texture& t : scene.textures) {
        if (t.type != TextureType::Standard) continue;
        if (t.embedded) // embedded in the scene file
            hashEmbedded(f, *t.embedded);
        else
            hashFileContents(f, t.path);
    }
    return f.h;
}

double adaptiveTarget(const Scene& scene, const RenderConfig& config) {
    if (!config.targetError || !config.adaptiveToTarget || config.sampleRange ||
        scene.settings.adaptiveThreshold > 0.0)
        return 0;
    return *config.targetError;
}

CheckpointKey checkpointKey(const Scene& scene, const RenderConfig& config, int sampleBase) {
    CheckpointKey k;
    k.version = SPILLWAY_VERSION;
    k.sceneHash = sceneHash(scene);
    k.environmentHash = environmentHash(scene);
    k.seed = scene.settings.seed;
    k.width = scene.image.width;
    k.height = scene.image.height;
    k.sampleBase = sampleBase;
    // Only the sorted backends round rays; the reference traces full ones.
    k.rayFormat = config.backend == BackendKind::Reference
                      ? "full"
                      : rayFormatName(config.pipeline.rayFormat);
    k.textureFilter = filterName(config.textureFilter);
    k.strategy = config.strategy;
    k.sampler = samplerName(scene.sampler);
    k.adaptiveThreshold = scene.settings.adaptiveThreshold;
    k.adaptiveMinSamples = scene.settings.adaptiveMinSamples;
    k.adaptiveTarget = adaptiveTarget(scene, config);
    return k;
}

std::string checkpointMismatch(const CheckpointKey& e, const CheckpointKey& f) {
    std::ostringstream why;
    auto differs = [&](const char* what, const auto& want, const auto& got) {
        if (!(want == got))
            why << (why.tellp() > 0 ? "; " : "") << what << " " << got << " where this render has "
                << want;
    };
    differs("Spillway version", e.version, f.version);
    if (e.sceneHash != f.sceneHash)
        why << (why.tellp() > 0 ? "; " : "")
            << "another scene (its file, meshes or textures differ)";
    if (e.environmentHash != f.environmentHash)
        why << (why.tellp() > 0 ? "; " : "")
            << "another environment (its radiance or its map's texels differ)";
    differs("seed", e.seed, f.seed);
    differs("width", e.width, f.width);
    differs("height", e.height, f.height);
    differs("sample base", e.sampleBase, f.sampleBase);
    differs("ray format", e.rayFormat, f.rayFormat);
    differs("texture filter", e.textureFilter, f.textureFilter);
    differs("sampling strategy", e.strategy, f.strategy);
    differs("sampler", e.sampler, f.sampler);
    differs("adaptive threshold", e.adaptiveThreshold, f.adaptiveThreshold);
    differs("adaptive min samples", e.adaptiveMinSamples, f.adaptiveMinSamples);
    if (e.adaptiveTarget != f.adaptiveTarget)
        why << (why.tellp() > 0 ? "; " : "") << "samples shared by the tiles toward "
            << (f.adaptiveTarget > 0 ? "relMSE " + shortText(f.adaptiveTarget)
                                     : std::string("no target (--uniform, or none)"))
            << " where this render shares them toward "
            << (e.adaptiveTarget > 0 ? "relMSE " + shortText(e.adaptiveTarget)
                                     : std::string("none (--uniform, or no --target-error)"));
    return why.str();
}

namespace {
// The checkpoint's channels, as writeCheckpoint lays them out: R, G, B, the home sums' words, the
// sample count, then each fine level's words. Returns the fine levels held, "1,2".
std::string nameChannels(const Film::State& film, size_t pixels, OIIO::ImageSpec& spec) {
    std::vector<OIIO::TypeDesc> formats(3, OIIO::TypeDesc::FLOAT);
    std::vector<std::string> names = {"R", "G", "B"};
    for (int k = 0; k < kSumsPerPixel; ++k)
        for (int w = 0; w < kWordsPerSum; ++w) {
            names.push_back(sumChannel(k, w));
            formats.push_back(OIIO::TypeDesc::UINT);
        }
    names.push_back("state.samples");
    formats.push_back(OIIO::TypeDesc::UINT);
    std::string levels;
    for (const Film::State::Level& l : film.levels) {
        if (l.sums.size() != pixels * kLevelSums)
            throw std::invalid_argument("checkpoint: a fine level of another size");
        levels += (levels.empty() ? "" : ",") + std::to_string(l.level);
        for (int k = 0; k < kLevelSums; ++k)
            for (int w = 0; w < kWordsPerSum; ++w) {
                names.push_back(levelChannel(l.level, k, w));
                formats.push_back(OIIO::TypeDesc::UINT);
            }
    }
    spec.channelnames = names;
    spec.channelformats = formats;
    return levels;
}
} // namespace

void writeCheckpoint(const std::string& path, const Checkpoint& c,
                     const std::vector<float>& image) {
    const size_t pixels = size_t(c.key.width) * size_t(c.key.height);
    if (image.size() != pixels * 3 || c.film.sums.size() != pixels * kSumsPerPixel ||
        c.film.samples.size() != pixels)
        throw std::invalid_argument("checkpoint: image and film sizes differ from the key's");
    const int channels = kChannels + kLevelChannels * int(c.film.levels.size());
    OIIO::ImageSpec spec(c.key.width, c.key.height, channels, OIIO::TypeDesc::FLOAT);
    const std::string levels = nameChannels(c.film, pixels, spec);
    spec.attribute("oiio:ColorSpace", "Linear");
    spec.attribute("Software", "Spillway");
    // RLE: a checkpoint interrupts the render while it is written, and the 128-bit sums' high
    // words are mostly zero. Measured at 1920x1080, 1 spp, twice each: none 2.9 s and 299 MB,
    // rle 1.4-1.8 s and 45 MB, zips 1.8-2.0 s and 31 MB.
    spec.attribute("compression", "rle");
    spec.attribute("spillway:checkpoint", 1);
    spec.attribute("spillway:version", c.key.version);
    spec.attribute("spillway:scene_hash", std::to_string(c.key.sceneHash));
    spec.attribute("spillway:environment_hash", std::to_string(c.key.environmentHash));
    spec.attribute("spillway:seed", std::to_string(c.key.seed));
    spec.attribute("spillway:sample_base", c.key.sampleBase);
    spec.attribute("spillway:ray_format", c.key.rayFormat);
    spec.attribute("spillway:texture_filter", c.key.textureFilter);
    spec.attribute("spillway:strategy", int(c.key.strategy));
    spec.attribute("spillway:sampler", c.key.sampler);
    spec.attribute("spillway:adaptive_threshold", std::to_string(c.key.adaptiveThreshold));
    spec.attribute("spillway:adaptive_min_samples", c.key.adaptiveMinSamples);
    spec.attribute("spillway:adaptive_target", exactText(c.key.adaptiveTarget));
    spec.attribute("spillway:iterations", c.iterations);
    spec.attribute("spillway:first_iteration", c.firstIteration);
    spec.attribute("spillway:total_iterations", c.totalIterations);
    spec.attribute("spillway:render_seconds", std::to_string(c.renderSeconds));
    spec.attribute("spillway:fixed_point_exponent", c.film.scaleExponent);
    spec.attribute("spillway:weight_exponent", c.film.weightExponent);
    spec.attribute("spillway:level_bits", c.film.levelBits);
    spec.attribute("spillway:fine_levels", levels);
    spec.attribute("spillway:non_finite_samples", std::to_string(c.film.nonFinite));
    spec.attribute("spillway:saturated_samples", std::to_string(c.film.saturated));
    spec.attribute("spillway:checksum", std::to_string(checkpointChecksum(c)));

    // Pixels as the channels lie: 3 floats, then 32 uint32 (the sums), then the sample count,
    // then 24 uint32 a fine level, each 4 bytes.
    std::vector<std::uint32_t> data(pixels * size_t(channels));
    for (size_t i = 0; i < pixels; ++i) {
        std::uint32_t* px = &data[i * size_t(channels)];
        std::memcpy(px, &image[i * 3], 3 * sizeof(float));
        for (int k = 0; k < kSumsPerPixel; ++k)
            putWords(c.film.sums[i * kSumsPerPixel + size_t(k)], px + 3 + kWordsPerSum * k);
        px[kSamplesChannel] = c.film.samples[i];
        for (size_t l = 0; l < c.film.levels.size(); ++l)
            for (int k = 0; k < kLevelSums; ++k)
                putWords(c.film.levels[l].sums[i * kLevelSums + size_t(k)],
                         px + kChannels + kLevelChannels * l + kWordsPerSum * k);
    }
    std::vector<unsigned char> bytes;
    OIIO::Filesystem::IOVecOutput proxy(bytes);
    auto out = OIIO::ImageOutput::create("checkpoint.exr", &proxy);
    if (!out) throw std::runtime_error("cannot write '" + path + "': " + OIIO::geterror());
    bool ok = out->open(path, spec) && out->write_image(OIIO::TypeDesc::UNKNOWN, data.data());
    std::string err = ok ? "" : out->geterror();
    if (!out->close() && ok) err = out->geterror(), ok = false;
    if (!ok) throw std::runtime_error("cannot write '" + path + "': " + err);
    writeFileAtomically(path, bytes.data(), bytes.size());
}

namespace {
// The index of a state channel (at least 3: R, G, B come first), checked to be uint32.
int stateChannel(const OIIO::ImageSpec& spec, const std::string& path, const std::string& name) {
    for (int c = 3; c < spec.nchannels; ++c)
        if (spec.channelnames[size_t(c)] == name) {
            if (spec.channelformat(c) != OIIO::TypeDesc::UINT)
                notACheckpoint(path, "channel " + name + " is not uint32");
            return c;
        }
    notACheckpoint(path, "no channel " + name);
}
} // namespace

namespace {
// The film's state channels, a block of rows at a time: what is allocated grows with the rows
// actually read, so a header that claims many pixels over a short or damaged file fails at its
// first missing block, having touched memory for the rows it held (fuzzing found files of a
// few hundred bytes that cost gigabytes when the whole film was allocated up front).
void readFilmState(OIIO::ImageInput& in, const std::string& path, const std::vector<size_t>& word,
                   Film::State& film) {
    const OIIO::ImageSpec& spec = in.spec();
    const size_t width = size_t(spec.width);
    const size_t kWords = size_t(spec.nchannels) - 3; // per pixel, as the file lists them
    const int rows = int(std::max<size_t>(1, (size_t(1) << 20) / (width * kWords)));
    std::vector<std::uint32_t> words;
    for (int y0 = 0; y0 < spec.height; y0 += rows) {
        const int y1 = std::min(spec.height, y0 + rows);
        words.resize(size_t(y1 - y0) * width * kWords);
        if (!in.read_scanlines(0, 0, spec.y + y0, spec.y + y1, 0, 3, spec.nchannels,
                               OIIO::TypeDesc::UINT, words.data()))
            throw std::runtime_error("cannot read checkpoint '" + path + "': " + in.geterror());
        const size_t first = size_t(y0) * width, end = size_t(y1) * width;
        film.sums.resize(end * kSumsPerPixel);
        film.samples.resize(end);
        for (Film::State::Level& l : film.levels)
            l.sums.resize(end * kLevelSums);
        for (size_t p = first; p < end; ++p) {
            const std::uint32_t* w = &words[(p - first) * kWords];
            // Sum k's words are word[4k .. 4k + 3]: the home sums, the fine levels' after them.
            auto sum = [&](size_t k) {
                unsigned __int128 bits = 0;
                for (size_t j = 0; j < kWordsPerSum; ++j)
                    bits = bits << 32 | w[word[kWordsPerSum * k + j]];
                return static_cast<Film::Fixed>(bits);
            };
            for (size_t k = 0; k < kSumsPerPixel; ++k)
                film.sums[p * kSumsPerPixel + k] = sum(k);
            film.samples[p] = w[word.back()];
            for (size_t l = 0; l < film.levels.size(); ++l)
                for (size_t k = 0; k < kLevelSums; ++k)
                    film.levels[l].sums[p * kLevelSums + k] =
                        sum(kSumsPerPixel + l * kLevelSums + k);
        }
    }
}
} // namespace

namespace {
// The fine levels a checkpoint says it holds (spillway:fine_levels, "1,3": each once, ascending,
// below 1000), their sums not yet read.
std::vector<Film::State::Level> levelsListed(const OIIO::ImageSpec& spec, const std::string& path) {
    std::vector<Film::State::Level> out;
    const std::string levels = spec.get_string_attribute("spillway:fine_levels");
    for (size_t at = 0; at < levels.size();) {
        const size_t comma = std::min(levels.find(',', at), levels.size());
        const std::string item = levels.substr(at, comma - at);
        const int last = out.empty() ? 0 : out.back().level;
        if (item.empty() || item.size() > 3 ||
            item.find_first_not_of("0123456789") != std::string::npos || std::stoi(item) <= last)
            notACheckpoint(path, "its spillway:fine_levels is not a list of levels");
        out.push_back({std::stoi(item), {}});
        at = comma + 1;
    }
    return out;
}
} // namespace

Checkpoint readCheckpoint(const std::string& path) {
    if (const std::string why = exrHeaderProblem(path); !why.empty()) notACheckpoint(path, why);
    // The OpenEXR reader alone: a checkpoint is an EXR, and a file that fails it is not one.
    // (ImageInput::open would then probe every other format's reader, a second or more each.)
    auto in = OIIO::ImageInput::create("openexr");
    OIIO::ImageSpec opened;
    if (!in || !in->open(path, opened))
        throw std::runtime_error("cannot read checkpoint '" + path +
                                 "': " + (in ? in->geterror() : OIIO::geterror()));
    const OIIO::ImageSpec& spec = in->spec();
    if (spec.get_int_attribute("spillway:checkpoint") != 1)
        notACheckpoint(path, "no spillway:checkpoint attribute");
    Checkpoint c;
    c.film.levels = levelsListed(spec, path);
    const int channels = kChannels + kLevelChannels * int(c.film.levels.size());
    if (spec.nchannels != channels || spec.width <= 0 || spec.height <= 0)
        notACheckpoint(path, "not " + std::to_string(channels) + " channels");
    if (const std::string why = imageSizeProblem(path, spec.width, spec.height); !why.empty())
        notACheckpoint(path, why); // before the film's 132 bytes a pixel are allocated
    // The state channels by name: OpenEXR keeps channels sorted, and OpenImageIO may list a
    // file's channels in another order than they were written.
    std::vector<size_t> word; // each state word's place among the file's channels 3 .. N
    for (int k = 0; k < kSumsPerPixel; ++k)
        for (int w = 0; w < kWordsPerSum; ++w)
            word.push_back(size_t(stateChannel(spec, path, sumChannel(k, w)) - 3));
    for (const Film::State::Level& l : c.film.levels)
        for (int k = 0; k < kLevelSums; ++k)
            for (int w = 0; w < kWordsPerSum; ++w)
                word.push_back(size_t(stateChannel(spec, path, levelChannel(l.level, k, w)) - 3));
    word.push_back(size_t(stateChannel(spec, path, "state.samples") - 3));
    c.key.version = spec.get_string_attribute("spillway:version");
    try {
        c.key.sceneHash = std::stoull(spec.get_string_attribute("spillway:scene_hash"));
        c.key.environmentHash = std::stoull(spec.get_string_attribute("spillway:environment_hash"));
        c.key.seed = std::uint32_t(std::stoul(spec.get_string_attribute("spillway:seed")));
        c.renderSeconds = std::stod(spec.get_string_attribute("spillway:render_seconds"));
        c.film.nonFinite = std::stoull(spec.get_string_attribute("spillway:non_finite_samples"));
        c.film.saturated = std::stoull(spec.get_string_attribute("spillway:saturated_samples"));
        c.key.adaptiveThreshold =
            std::stod(spec.get_string_attribute("spillway:adaptive_threshold"));
        // Absent: no target (checkpoints made before it was kept had none that resumed alike).
        const std::string target = spec.get_string_attribute("spillway:adaptive_target");
        c.key.adaptiveTarget = target.empty() ? 0.0 : std::stod(target);
    } catch (const std::exception&) {
        notACheckpoint(path, "its spillway:* metadata is incomplete");
    }
    c.key.width = spec.width;
    c.key.height = spec.height;
    c.key.sampleBase = spec.get_int_attribute("spillway:sample_base");
    c.key.rayFormat = spec.get_string_attribute("spillway:ray_format");
    c.key.textureFilter = spec.get_string_attribute("spillway:texture_filter");
    c.key.strategy = std::uint32_t(spec.get_int_attribute("spillway:strategy"));
    c.key.sampler = spec.get_string_attribute("spillway:sampler");
    c.key.adaptiveMinSamples = spec.get_int_attribute("spillway:adaptive_min_samples");
    c.film.scaleExponent = spec.get_int_attribute("spillway:fixed_point_exponent");
    c.film.weightExponent = spec.get_int_attribute("spillway:weight_exponent");
    c.film.levelBits = spec.get_int_attribute("spillway:level_bits");
    c.iterations = spec.get_int_attribute("spillway:iterations", -1);
    c.firstIteration = spec.get_int_attribute("spillway:first_iteration", -1);
    c.totalIterations = spec.get_int_attribute("spillway:total_iterations", -1);
    if (c.iterations < 0 || c.firstIteration < 0 || c.totalIterations < 0 || c.key.sampleBase <= 0)
        notACheckpoint(path, "its spillway:* metadata is incomplete");

    readFilmState(*in, path, word, c.film);
    std::uint64_t checksum = 0;
    try {
        checksum = std::stoull(spec.get_string_attribute("spillway:checksum"));
    } catch (const std::exception&) {
        notACheckpoint(path, "it has no spillway:checksum");
    }
    if (checksum != checkpointChecksum(c))
        notACheckpoint(path, "its contents do not match its checksum (the file is damaged, or "
                             "was edited)");
    checkProgress(path, c);
    return c;
}

namespace {
// to's fine levels plus from's, level by level (the union, ascending).
void addLevels(const Film::State& from, Film::State& to) {
    for (const Film::State::Level& l : from.levels) {
        if (l.sums.size() * 8 != to.sums.size() * 6)
            throw std::invalid_argument("a partial's fine level is of another film size");
        auto at = std::lower_bound(
            to.levels.begin(), to.levels.end(), l.level,
            [](const Film::State::Level& a, int level) { return a.level < level; });
        if (at == to.levels.end() || at->level != l.level) {
            at = to.levels.insert(at, l);
            continue;
        }
        for (size_t i = 0; i < l.sums.size(); ++i)
            at->sums[i] += l.sums[i];
    }
}
} // namespace

Checkpoint mergePartials(const std::vector<std::pair<std::string, Checkpoint>>& partials) {
    if (partials.empty()) throw std::invalid_argument("merge needs at least one partial render");
    std::vector<const std::pair<std::string, Checkpoint>*> order;
    for (const auto& p : partials)
        order.push_back(&p);
    std::sort(order.begin(), order.end(), [](const auto* a, const auto* b) {
        return a->second.firstIteration < b->second.firstIteration;
    });
    const Checkpoint& head = order.front()->second;
    const int spi = head.key.sampleBase * head.key.sampleBase;
    auto samples = [&](int iteration) { return std::to_string(iteration * spi); };
    Checkpoint merged = head;
    merged.firstIteration = 0;
    merged.iterations = 0;
    merged.renderSeconds = 0;
    std::fill(merged.film.sums.begin(), merged.film.sums.end(), 0);
    merged.film.levels.clear();
    std::fill(merged.film.samples.begin(), merged.film.samples.end(), 0u);
    merged.film.nonFinite = merged.film.saturated = 0;
    int next = 0; // the first iteration not yet covered
    for (const auto* p : order) {
        const std::string& file = p->first;
        const Checkpoint& c = p->second;
        if (const std::string why = checkpointMismatch(head.key, c.key); !why.empty())
            throw std::invalid_argument(file + " is a partial of another render than " +
                                        order.front()->first + ": " + why);
        if (c.film.scaleExponent != head.film.scaleExponent ||
            c.film.weightExponent != head.film.weightExponent ||
            c.film.levelBits != head.film.levelBits || c.film.sums.size() != head.film.sums.size())
            throw std::invalid_argument(file + "'s film differs from " + order.front()->first +
                                        "'s");
        if (c.totalIterations != head.totalIterations)
            throw std::invalid_argument(file + " is a partial of a " + samples(c.totalIterations) +
                                        "-spp render, " + order.front()->first + " of a " +
                                        samples(head.totalIterations) + "-spp one");
        const std::string range =
            samples(c.firstIteration) + ":" + samples(c.firstIteration + c.iterations);
        if (c.firstIteration < next)
            throw std::invalid_argument(file + " (samples " + range +
                                        ") overlaps the samples before " + samples(next));
        if (c.firstIteration > next)
            throw std::invalid_argument("no partial holds samples " + samples(next) + ":" +
                                        samples(c.firstIteration) + " (the next, " + file +
                                        ", starts at " + samples(c.firstIteration) + ")");
        for (size_t i = 0; i < merged.film.sums.size(); ++i)
            merged.film.sums[i] += c.film.sums[i];
        addLevels(c.film, merged.film);
        for (size_t i = 0; i < merged.film.samples.size(); ++i)
            merged.film.samples[i] += c.film.samples[i];
        merged.film.nonFinite += c.film.nonFinite;
        merged.film.saturated += c.film.saturated;
        merged.renderSeconds += c.renderSeconds;
        merged.iterations += c.iterations;
        next = c.firstIteration + c.iterations;
    }
    if (next != head.totalIterations)
        throw std::invalid_argument("no partial holds samples " + samples(next) + ":" +
                                    samples(head.totalIterations));
    return merged;
}

} // namespace spw
