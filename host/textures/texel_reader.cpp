// TexelReader (texel_reader.h): a run of lookups in one image filtered on the tiles the thread
// holds, level by level, 8-bit runs SIMD-wide (wide_texels.h), the rest one texel at a time, each
// texel decoded to linear values.
#include "host/textures/texel_reader.h"

#include "host/image/image_io.h"

#include <OpenImageIO/half.h>

#include <algorithm>
#include <cmath>
#include <cstring>

namespace spw {

void TexelReader::lookups(size_t n, const vec2* uv, const float* footprint, vec3* out) {
    thread_local std::vector<LevelQuery> queries;
    queries.resize(n);
    const int last = int(image_.levels.size()) - 1;
    for (size_t k = 0; k < n; ++k) {
        LevelQuery& q = queries[k];
        q.s = uv[k].x, q.t = 1.0f - uv[k].y;
        q.level = 0, q.blend = -1.0f;
        const float texels = (footprint ? footprint[k] : 0.0f) * image_.finest;
        if (!(texels > 1.0f) || last == 0) continue;
        const float lod = std::log2(texels);
        if (!(lod < float(last))) { // an infinite footprint too
            q.level = last;
            continue;
        }
        q.level = int(lod);
        q.blend = lod - float(q.level);
    }
    filterLevel(queries.data(), n, 0, out);
    thread_local std::vector<vec3> coarse;
    coarse.resize(n);
    filterLevel(queries.data(), n, 1, coarse.data());
    for (size_t k = 0; k < n; ++k) {
        const LevelQuery& q = queries[k];
        if (q.blend >= 0.0f) out[k] = out[k] + q.blend * (coarse[k] - out[k]);
    }
}

void TexelReader::finestLevel(std::vector<vec3>& out) {
    const Impl::Level& level = image_.levels[0];
    out.resize(size_t(level.width) * size_t(level.height));
    for (int y = 0; y < level.height; ++y)
        for (int x = 0; x < level.width; ++x)
            out[size_t(y) * size_t(level.width) + size_t(x)] =
                image_.absent ? vec3(1.0f) : texel(0, level.x + x, level.y + y);
}

void TexelReader::filterLevel(const LevelQuery* queries, size_t n, int up, vec3* out) {
    auto reads = [&](size_t k) { return up == 0 || queries[k].blend >= 0.0f; };
    if (!(impl_.wide && image_.eightBit && n >= kWideFrom)) {
        for (size_t k = 0; k < n; ++k)
            if (reads(k)) out[k] = bilinear(queries[k].level + up, queries[k].s, queries[k].t);
        return;
    }
    // The hits in order of their level (a counting sort: a run's footprints differ, and its
    // levels with them, so hits of one level would otherwise come a few at a time).
    std::array<std::uint32_t, kMaxLevels + 1> first{};
    for (size_t k = 0; k < n; ++k)
        if (reads(k)) ++first[size_t(queries[k].level + up) + 1];
    for (size_t l = 1; l <= kMaxLevels; ++l)
        first[l] += first[l - 1];
    thread_local std::vector<std::uint32_t> byLevel;
    byLevel.resize(n);
    for (size_t k = 0; k < n; ++k)
        if (reads(k)) byLevel[first[size_t(queries[k].level + up)]++] = std::uint32_t(k);
    // Blocks of one level's hits.
    TexelLanes lanes;
    std::uint32_t hitOf[simd::kBlock];
    size_t count = 0;
    int blockLevel = -1;
    for (size_t i = 0, total = first[kMaxLevels - 1]; i < total; ++i) {
        const std::uint32_t k = byLevel[i];
        const int level = queries[k].level + up;
        if (level != blockLevel || count == simd::kBlock) {
            filterBlock(blockLevel, lanes, hitOf, count, out);
            blockLevel = level;
            count = 0;
        }
        lanes.s.v[count] = queries[k].s, lanes.t.v[count] = queries[k].t, hitOf[count++] = k;
    }
    filterBlock(blockLevel, lanes, hitOf, count, out);
}

void TexelReader::filterBlock(int level, TexelLanes& lanes, std::uint32_t* hitOf, size_t count,
                              vec3* out) {
    float *const s = lanes.s.v, *const t = lanes.t.v;
    while (count > 0) {
        size_t left = 0;
        const TexelTile tile = heldTile(level);
        if (tile.bytes >= 4 && count >= kWideFrom) {
            const size_t end = simd::wholeVectors(count);
            for (size_t k = count; k < end; ++k) // padding repeats the last lane
                s[k] = s[count - 1], t[k] = t[count - 1];
            bilinearInTile(tile, levelView(level), end, lanes);
            for (size_t k = 0; k < count; ++k) {
                if (lanes.done.v[k])
                    out[hitOf[k]] = vec3(lanes.r.v[k], lanes.g.v[k], lanes.b.v[k]);
                else
                    s[left] = s[k], t[left] = t[k], hitOf[left++] = hitOf[k];
            }
        } else {
            left = count;
        }
        if (left == 0) return;
        out[hitOf[0]] = bilinear(level, s[0], t[0]);
        for (size_t k = 1; k < left; ++k)
            s[k - 1] = s[k], t[k - 1] = t[k], hitOf[k - 1] = hitOf[k];
        count = left - 1;
    }
}

TexelTile TexelReader::heldTile(int levelIndex) const {
    const Held& h = held_[size_t(levelIndex)];
    TexelTile tile;
    if (!h.tile || h.type != OIIO::TypeDesc::UINT8) return tile;
    // The channels read start Texture::channel bytes into each texel.
    tile.pixels = h.pixels + image_.firstChannel;
    tile.x0 = h.x0, tile.y0 = h.y0, tile.x1 = h.x1, tile.y1 = h.y1;
    tile.pixelBytes = int(h.pixelBytes), tile.rowBytes = int(h.rowBytes);
    tile.bytes = int(h.bytes()) - image_.firstChannel;
    tile.channels = std::min(image_.channels, 3);
    tile.decode = image_.srgb ? srgbTable().data() : linearTable().data();
    return tile;
}

TexelLevel TexelReader::levelView(int levelIndex) const {
    const Impl::Level& l = image_.levels[size_t(levelIndex)];
    return {l.x, l.y, l.width, l.height};
}

vec3 TexelReader::bilinear(int levelIndex, float s, float t) {
    const Impl::Level& level = image_.levels[size_t(levelIndex)];
    // Periodic: only the fraction matters, and it keeps far coordinates exact.
    s -= std::floor(s);
    t -= std::floor(t);
    if (!(s >= 0.0f && s <= 1.0f)) s = 0.0f; // a NaN coordinate reads texel 0
    if (!(t >= 0.0f && t <= 1.0f)) t = 0.0f;
    // Texel centres at (i + 0.5) / width.
    const float x = s * float(level.width) - 0.5f, y = t * float(level.height) - 0.5f;
    const float xf = std::floor(x), yf = std::floor(y);
    const float ax = x - xf, ay = y - yf;
    const int x0 = wrap(int(xf), level.width) + level.x, y0 = wrap(int(yf), level.height) + level.y;
    const int x1 = x0 + 1 == level.x + level.width ? level.x : x0 + 1;
    const int y1 = y0 + 1 == level.y + level.height ? level.y : y0 + 1;
    vec3 a, b, c, d;
    const Held& h = held_[size_t(levelIndex)];
    if (h.holds(x0, y0) && h.holds(x1, y1)) {
        // The common case: all four texels in the tile the previous lookup read.
        a = decode(h, h.at(x0, y0)), b = decode(h, h.at(x1, y0));
        c = decode(h, h.at(x0, y1)), d = decode(h, h.at(x1, y1));
    } else {
        a = texel(levelIndex, x0, y0), b = texel(levelIndex, x1, y0);
        c = texel(levelIndex, x0, y1), d = texel(levelIndex, x1, y1);
    }
    const vec3 top = a + ax * (b - a), bottom = c + ax * (d - c);
    return top + ay * (bottom - top);
}

vec3 TexelReader::texel(int levelIndex, int x, int y) {
    Held& h = held_[size_t(levelIndex)];
    if (!h.holds(x, y)) {
        const auto slot = std::uint32_t(image_.firstHeld + size_t(levelIndex));
        if (h.tile) {
            impl_.cache->release_tile(h.tile);
            thread_.heldBytes -= h.bytes();
        } else {
            thread_.holding.push_back(slot);
        }
        h = Held{};
        OIIO::ImageCache::ImageHandle* handle = impl_.handleOf(image_, index_);
        h.tile =
            handle ? impl_.cache->get_tile(handle, thread_.oiio, 0, levelIndex, x, y, 0) : nullptr;
        if (!h.tile) {
            // The slot holds nothing now (a slot is listed while it holds a tile).
            thread_.holding.erase(std::find(thread_.holding.begin(), thread_.holding.end(), slot));
            impl_.fail(index_);
            return vec3(0.0f);
        }
        const OIIO::ROI roi = impl_.cache->tile_roi(h.tile);
        OIIO::TypeDesc format;
        h.pixels = static_cast<const unsigned char*>(impl_.cache->tile_pixels(h.tile, format));
        h.x0 = roi.xbegin, h.x1 = roi.xend, h.y0 = roi.ybegin, h.y1 = roi.yend;
        h.type = OIIO::TypeDesc::BASETYPE(format.basetype);
        h.pixelBytes = format.size() * size_t(roi.nchannels());
        h.rowBytes = h.pixelBytes * size_t(roi.width());
        if (!h.pixels || !h.holds(x, y)) {
            impl_.fail(index_);
            h.x1 = h.x0, h.y1 = h.y0; // holds nothing
            return vec3(0.0f);
        }
        thread_.heldBytes += h.bytes();
        if (thread_.heldBytes > impl_.heldLimit) impl_.letGo(thread_, slot);
    }
    return decode(h, h.at(x, y));
}

vec3 TexelReader::decode(const Held& h, const unsigned char* texel) const {
    const unsigned char* p = texel + size_t(image_.firstChannel) * channelBytes(h.type);
    float v[3] = {0.0f, 0.0f, 0.0f};
    const int nc = std::min(image_.channels, 3);
    if (h.type == OIIO::TypeDesc::UINT8) {
        const std::array<float, 256>& table = image_.srgb ? srgbTable() : linearTable();
        for (int c = 0; c < nc; ++c)
            v[c] = table[p[c]];
    } else {
        for (int c = 0; c < nc; ++c)
            v[c] = image_.srgb ? srgbToLinear(channel(p, c, h.type)) : channel(p, c, h.type);
    }
    return nc == 1 ? vec3(v[0]) : vec3(v[0], v[1], v[2]);
}

const std::array<float, 256>& TexelReader::srgbTable() {
    static const std::array<float, 256> table = [] {
        std::array<float, 256> t{};
        for (int i = 0; i < 256; ++i)
            t[size_t(i)] = srgbToLinear(float(i) * (1.0f / 255.0f));
        return t;
    }();
    return table;
}

const std::array<float, 256>& TexelReader::linearTable() {
    static const std::array<float, 256> table = [] {
        std::array<float, 256> t{};
        for (int i = 0; i < 256; ++i)
            t[size_t(i)] = float(i) * (1.0f / 255.0f);
        return t;
    }();
    return table;
}

size_t TexelReader::channelBytes(OIIO::TypeDesc::BASETYPE type) {
    return type == OIIO::TypeDesc::UINT8                                    ? 1
           : type == OIIO::TypeDesc::UINT16 || type == OIIO::TypeDesc::HALF ? 2
                                                                            : 4;
}

float TexelReader::channel(const unsigned char* p, int c, OIIO::TypeDesc::BASETYPE type) {
    switch (type) {
    case OIIO::TypeDesc::UINT16: {
        std::uint16_t u;
        std::memcpy(&u, p + 2 * c, 2);
        return float(u) * (1.0f / 65535.0f);
    }
    case OIIO::TypeDesc::HALF: {
        half h;
        std::memcpy(&h, p + 2 * c, 2);
        return float(h);
    }
    default: {
        float f;
        std::memcpy(&f, p + 4 * c, 4);
        return f;
    }
    }
}

} // namespace spw
