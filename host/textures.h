// Texture trees (Constant, Standard, Layered) resolved to an albedo per hit. Image textures go
// through OpenImageIO's TextureSystem, which opens files lazily and reads only the tiles and MIP
// levels that lookups touch; the system is created only when a scene has a Standard texture.
// 8-bit images are taken to be sRGB-encoded and linearised after the lookup.
#pragma once

#include "host/scene.h"

#include <memory>
#include <vector>

namespace spw {

class TextureResolver {
  public:
    explicit TextureResolver(const Scene& scene);
    ~TextureResolver();
    TextureResolver(const TextureResolver&) = delete;
    TextureResolver& operator=(const TextureResolver&) = delete;

    // reflectance x (texture colour at uv, or the constant colour). Thread-safe.
    vec3 albedo(const Shader& shader, vec2 uv) const;
    // True when the scene has image textures (OpenImageIO is in use).
    bool active() const { return impl_ != nullptr; }

  private:
    vec3 eval(int texture, vec2 uv) const;
    struct Impl;
    const Scene& scene_;
    std::unique_ptr<Impl> impl_;
};

} // namespace spw
