// Texture trees (Constant, Standard, Layered) resolved to an albedo per hit. Image files go
// through OpenImageIO's ImageCache, which opens them lazily and reads only the tiles and MIP
// levels that lookups touch; the cache is created only when a scene has a Standard texture. The
// filtering (bilinear, trilinear across MIP levels) is done here, on the cache's tiles: a run of
// lookups in one image holds the tiles it last read, so sorted hits rarely go back to the cache.
// (OpenImageIO's own TextureSystem::texture took about 400 ns a lookup, and its batched entry
// point loops over the single one in the 2.4 that Debian ships.)
// 8-bit images are taken to be sRGB-encoded and linearised after the lookup.
//
// A texture tree may share subtrees (a YAML alias used several times): it is a DAG, and each
// shader's is flattened once into a program that evaluates every node once per lookup, in
// children-first order, so sharing never multiplies work.
#pragma once

#include "host/scene/scene.h"

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace spw {

// What the texture lookups and OpenImageIO's tile cache did during a render.
struct TextureStatistics {
    std::uint64_t lookups = 0;        // lookups (one per Standard node per hit set up)
    std::uint64_t tilesRead = 0;      // tiles read into the cache, re-reads after eviction too
    std::uint64_t bytesRead = 0;      // pixel bytes those tiles held (uncompressed)
    std::uint64_t filesOpened = 0;    // file opens, re-opens after closing included
    std::uint64_t filesReopened = 0;  // opens beyond the first of each file
    std::uint64_t cacheMisses = 0;    // tile lookups that missed the cache
    std::uint64_t peakCacheBytes = 0; // the tile cache's largest size seen (noteCacheUse)
    std::uint64_t tiledCopies = 0;    // large untiled images given tiled copies (tiled_copy.h)
    std::uint64_t tiledCopyBytes = 0; // the pixel bytes written to them
    double tiledCopySeconds = 0.0;    // the time making them took
};

class TextureResolver {
  public:
    // cacheMiB: the tile cache's size (settings: texture cache, or --texture-cache). filtered:
    // lookups take their footprint (MIP levels, trilinear); otherwise the finest level always.
    // wide: albedos() filters runs of lookups in 8-bit images and blends Layered textures
    // SIMD-wide (wide_texels.h); false, one lookup at a time. The values are the same to the
    // bit. scratch: the folder for tiled copies of large untiled images (tiled_copy.h), as
    // --spill-dir names it (empty: the system temp folder, image/scratch_file.h).
    TextureResolver(const Scene& scene, double cacheMiB, bool filtered = true, bool wide = true,
                    const std::string& scratch = "");
    ~TextureResolver();
    TextureResolver(const TextureResolver&) = delete;
    TextureResolver& operator=(const TextureResolver&) = delete;

    // reflectance x (texture colour at uv, or the constant colour). `footprint`: the filter
    // width in texture space (uv units), from the ray cone; it picks the MIP levels (trilinear).
    // Thread-safe.
    vec3 albedo(const Shader& shader, vec2 uv, float footprint) const;
    // The same for `n` hits of one shader (each out[k] what that hit alone gets, bit for bit),
    // evaluated texture by texture: every hit's lookups in one file, then in the next; within a
    // file MIP level by level, and SIMD-wide where the image is 8-bit. The
    // sorted pipeline's hits of a shader arrive together, near each other in texture space, so
    // consecutive lookups read the tiles the previous one held, where one hit's lookups in turn
    // would switch file every time.
    void albedos(const Shader& shader, size_t n, const vec2* uv, const float* footprint,
                 vec3* out) const;
    // The values of the texture tree rooted at Scene::textures[tree] (one a shader uses: its
    // colour's, normal map's, metallic-roughness image's or cut-out's) for n lookups, as albedos()
    // evaluates them; footprint null: the finest level. Thread-safe.
    void values(int tree, size_t n, const vec2* uv, const float* footprint, vec3* out) const;
    // The finest MIP level of the image of Standard texture Scene::textures[texture], as lookups
    // read it (linear, its channels from Texture::channel on), row by row from the top, and its
    // size. Throws SceneError where its pixels cannot be read.
    std::vector<vec3> finestLevel(int texture, int& width, int& height) const;
    // Makes, in parallel, the tiled copies (tiled_copy.h) not yet made of the images that
    // shaders s with shaders[s] read: the sorted pipeline calls it with a batch's shaders before
    // its lookups, which would otherwise make each copy on its first lookup, one at a time as
    // the hits sorted by shader reach it. Only images a ray reads are ever copied.
    void prepare(const std::vector<bool>& shaders) const;
    // Whether some tiled copy is not made yet (prepare has work to do).
    bool copiesPending() const;
    // True when the scene has image textures (OpenImageIO is in use).
    bool active() const { return impl_ != nullptr; }
    // True when the images hit setup reads (every MIP level, as the tile cache holds them) total
    // more than the cache's budget: tiles are then evicted and read again, as often as the order
    // of the lookups makes them.
    bool outgrowsCache() const { return outgrowsCache_; }
    // Throws SceneError (the texture's file and scene line) if an image lookup failed since the
    // scene loaded: a file that was readable when loaded but whose pixels are not; or
    // std::runtime_error where a tiled copy could not be written (the scratch folder).
    void checkErrors() const;
    // Samples the tile cache's size for peakCacheBytes (the renderer calls it per iteration).
    void noteCacheUse() const;
    // OpenImageIO's counters since the resolver was made; all zero when !active().
    TextureStatistics statistics() const;

    struct Impl; // OpenImageIO's tile cache and what the lookups know of each image

  private:
    // One node of a flattened tree: its operands are slots of earlier nodes.
    struct Op {
        TextureType type;
        int texture;            // index into Scene::textures
        int upper, lower, mask; // Layered: operand slots
    };
    // The Standard textures of the tree rooted at `root` (compiled), appended to `out`.
    void standardNodes(int root, std::vector<int>& out) const;
    // The trees of Scene::textures that shaders read, flattened into programs_.
    void compilePrograms();
    // The tree's values for n lookups, in a per-thread buffer that the next call reuses.
    const vec3* evaluate(int tree, size_t n, const vec2* uv, const float* footprint) const;

    const Scene& scene_;
    std::vector<std::vector<Op>> programs_; // per Scene::textures root used by a shader
    std::unique_ptr<Impl> impl_;
    bool wide_ = true;
    bool outgrowsCache_ = false;
};

} // namespace spw
