#include "host/textures.h"

#include "host/image_io.h"

#include <OpenImageIO/texture.h>

#include <cmath>
#include <stdexcept>

namespace spw {

struct TextureResolver::Impl {
    OIIO::TextureSystem* system = nullptr;
    struct Image {
        OIIO::TextureSystem::TextureHandle* handle = nullptr;
        bool srgb = false;
        int channels = 3;
    };
    std::vector<Image> images; // parallel to Scene::textures (only Standard entries are used)
    ~Impl() {
        if (system) OIIO::TextureSystem::destroy(system);
    }
};

TextureResolver::TextureResolver(const Scene& scene) : scene_(scene) {
    bool any = false;
    for (const Texture& t : scene.textures) any = any || t.type == TextureType::Standard;
    if (!any) return;
    impl_ = std::make_unique<Impl>();
    impl_->system = OIIO::TextureSystem::create(false);
    impl_->system->attribute("max_memory_MB", 256.0f);
    impl_->images.resize(scene.textures.size());
    for (size_t i = 0; i < scene.textures.size(); ++i) {
        const Texture& t = scene.textures[i];
        if (t.type != TextureType::Standard) continue;
        Impl::Image& img = impl_->images[i];
        OIIO::ustring name(t.path);
        img.handle = impl_->system->get_texture_handle(name);
        const OIIO::ImageSpec* spec = img.handle ? impl_->system->imagespec(img.handle, nullptr, 0) : nullptr;
        if (!spec)
            throw std::runtime_error("cannot read texture '" + t.path + "': " + impl_->system->geterror());
        img.channels = spec->nchannels;
        std::string cs = spec->get_string_attribute("oiio:ColorSpace");
        img.srgb = cs == "sRGB" || (cs.empty() && spec->format == OIIO::TypeDesc::UINT8);
    }
}

TextureResolver::~TextureResolver() = default;

vec3 TextureResolver::eval(int index, vec2 uv) const {
    const Texture& t = scene_.textures[size_t(index)];
    switch (t.type) {
    case TextureType::Constant:
        return t.colour;
    case TextureType::Layered: {
        vec3 m = eval(t.mask, uv);
        return m * eval(t.upper, uv) + (vec3(1.0f) - m) * eval(t.lower, uv);
    }
    case TextureType::Standard: {
        const Impl::Image& img = impl_->images[size_t(index)];
        OIIO::TextureOpt opt;
        opt.swrap = opt.twrap = OIIO::TextureOpt::WrapPeriodic;
        opt.interpmode = OIIO::TextureOpt::InterpBilinear;
        float rgb[4] = {0, 0, 0, 0};
        int nc = std::min(img.channels, 3);
        // OBJ's v grows upwards, image rows downwards. Zero derivatives: the finest MIP level.
        impl_->system->texture(img.handle, impl_->system->get_perthread_info(), opt, uv.x, 1.0f - uv.y,
                               0, 0, 0, 0, nc, rgb);
        vec3 c = nc == 1 ? vec3(rgb[0]) : vec3(rgb[0], rgb[1], rgb[2]);
        if (img.srgb) c = vec3(srgbToLinear(c.x), srgbToLinear(c.y), srgbToLinear(c.z));
        return c;
    }
    }
    return vec3(0.0f);
}

vec3 TextureResolver::albedo(const Shader& shader, vec2 uv) const {
    const ShaderParams& p = shader.params;
    if (shader.texture < 0) return p.colour * p.reflectance;
    return eval(shader.texture, uv) * p.reflectance;
}

} // namespace spw
