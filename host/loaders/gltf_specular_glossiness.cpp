// GltfReader's KHR_materials_pbrSpecularGlossiness (older assets' workflow), converted to
// metallic-roughness as the extension's converters do: its factors, and its images texel by
// texel into a base colour and a metallic-roughness image held in memory.
#include "host/image/image_io.h"
#include "host/loaders/gltf_reader.h"

#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cmath>

namespace spw {

namespace {

// The conversion of KHR_materials_pbrSpecularGlossiness's values to metallic-roughness that
// the extension's converters use (glTF-Transform's, Babylon.js's): the metallic that gives the
// diffuse and specular colours' perceived brightnesses, solved from F0 = 0.04 (1 - m) + base m,
// and the base colour blended between what the diffuse and the specular colours imply.
struct MetallicRoughness {
    vec3 base;
    double metallic;
};

constexpr double kDielectric = 0.04;

double perceived(vec3 c) {
    return std::sqrt(0.299 * c.x * c.x + 0.587 * c.y * c.y + 0.114 * c.z * c.z);
}

MetallicRoughness fromSpecularGlossiness(vec3 diffuse, vec3 specular) {
    constexpr double kTiny = 1e-6;
    const double keep = 1.0 - std::max({specular.x, specular.y, specular.z});
    const double d = perceived(diffuse), sp = perceived(specular);
    double m = 0.0;
    if (sp >= kDielectric) {
        const double a = kDielectric, b = d * keep / (1.0 - a) + sp - 2.0 * a, c = a - sp;
        m = std::clamp((-b + std::sqrt(std::max(b * b - 4.0 * a * c, 0.0))) / (2.0 * a), 0.0, 1.0);
    }
    MetallicRoughness out{vec3(0.0f), m};
    for (int k = 0; k < 3; ++k) {
        const double fromDiffuse =
            diffuse[k] * keep / (1.0 - kDielectric) / std::max(1.0 - m, kTiny);
        const double fromSpecular = (specular[k] - kDielectric * (1.0 - m)) / std::max(m, kTiny);
        out.base[k] =
            float(std::clamp(fromDiffuse + (fromSpecular - fromDiffuse) * m * m, 0.0, 1.0));
    }
    return out;
}

// One image's texels as a bake of width x height texels reads them, a row at a time from the
// top: texel (x, y) of the bake is the image's texel it falls in. Linear RGBA: a grey image's
// grey in each colour channel, a missing alpha 1, colour decoded from sRGB where the image is
// stored so (as texture lookups decode it, host/textures/textures.cpp).
class TexelRows {
  public:
    TexelRows(OIIO::ImageInput& in, int width, int height)
        : in_(in), spec_(in.spec()), height_(height), columns_(size_t(width)),
          row_(size_t(spec_.width) * size_t(spec_.nchannels)) {
        const std::string cs = spec_.get_string_attribute("oiio:ColorSpace");
        srgb_ = cs == "sRGB" || (cs.empty() && spec_.format == OIIO::TypeDesc::UINT8);
        for (int x = 0; x < width; ++x)
            columns_[size_t(x)] = int((double(x) + 0.5) * spec_.width / width);
    }

    // Moves to row y of the bake (y increasing); false where the image cannot be read.
    bool seek(int y) {
        const int wanted = int((double(y) + 0.5) * spec_.height / height_);
        while (read_ < wanted) {
            ++read_;
            if (!in_.read_scanlines(0, 0, read_, read_ + 1, 0, 0, spec_.nchannels,
                                    OIIO::TypeDesc::FLOAT, row_.data()))
                return false;
        }
        return true;
    }

    glm::vec4 at(int x) const {
        const float* p = &row_[size_t(columns_[size_t(x)]) * size_t(spec_.nchannels)];
        const int n = spec_.nchannels;
        const bool grey = n <= 2;
        glm::vec4 t(1.0f);
        for (int k = 0; k < 3; ++k) {
            const float v = p[grey ? 0 : k];
            t[k] = srgb_ ? srgbToLinear(v) : v;
        }
        if (n == 2 || n >= 4) t.w = p[n == 2 ? 1 : 3];
        return t;
    }

  private:
    OIIO::ImageInput& in_;
    OIIO::ImageSpec spec_;
    int height_, read_ = -1;
    bool srgb_ = false;
    std::vector<int> columns_;
    std::vector<float> row_;
};

// A PNG written to memory a row at a time: 8-bit, RGBA or RGB.
class PngInMemory {
  public:
    PngInMemory(int width, int height, int channels)
        : proxy_(bytes_), out_(OIIO::ImageOutput::create("baked.png")) {
        OIIO::ImageSpec spec(width, height, channels, OIIO::TypeDesc::UINT8);
        void* proxy = &proxy_;
        spec.attribute("oiio:ioproxy", OIIO::TypeDesc::PTR, &proxy);
        if (!out_ || !out_->open("baked.png", spec))
            throw std::runtime_error("cannot encode a PNG in memory: " + OIIO::geterror());
    }
    void row(int y, const std::vector<std::uint8_t>& texels) {
        if (!out_->write_scanline(y, 0, OIIO::TypeDesc::UINT8, texels.data()))
            throw std::runtime_error("cannot encode a PNG in memory: " + out_->geterror());
    }
    // The image's bytes, once every row is written.
    std::shared_ptr<const EmbeddedImage> finish() {
        if (!out_->close())
            throw std::runtime_error("cannot encode a PNG in memory: " + out_->geterror());
        auto image = std::make_shared<EmbeddedImage>();
        image->bytes = std::make_shared<const std::string>(bytes_.begin(), bytes_.end());
        image->length = bytes_.size();
        return image;
    }

  private:
    std::vector<unsigned char> bytes_;
    OIIO::Filesystem::IOVecOutput proxy_;
    std::unique_ptr<OIIO::ImageOutput> out_;
};

std::uint8_t unit8(double v) {
    return std::uint8_t(std::lround(std::clamp(v, 0.0, 1.0) * 255.0));
}

// A row of the bake, from the diffuse and specular-glossiness images' texels (1 where there is
// none) times the factors: RGBA sRGB base colour texels, and RGB metallic-roughness ones (red,
// glTF's occlusion, unread).
void convertRow(const TexelRows* diffuseTexels, const TexelRows* specularTexels, glm::vec4 diffuse,
                vec3 specular, double glossiness, std::vector<std::uint8_t>& base,
                std::vector<std::uint8_t>& metallicRoughness) {
    for (size_t x = 0; x < base.size() / 4; ++x) {
        const glm::vec4 d = diffuse * (diffuseTexels ? diffuseTexels->at(int(x)) : glm::vec4(1));
        const glm::vec4 s = specularTexels ? specularTexels->at(int(x)) : glm::vec4(1);
        const MetallicRoughness mr = fromSpecularGlossiness(vec3(d), specular * vec3(s));
        for (size_t k = 0; k < 3; ++k)
            base[x * 4 + k] = linearToSrgb8(mr.base[int(k)]);
        base[x * 4 + 3] = unit8(d.w);
        metallicRoughness[x * 3] = 255;
        metallicRoughness[x * 3 + 1] = unit8(1.0 - glossiness * s.w);
        metallicRoughness[x * 3 + 2] = unit8(mr.metallic);
    }
}

} // namespace

const tinygltf::Material&
GltfReader::readSpecularGlossiness(const tinygltf::Material& mat, const std::string& at,
                                   const std::string& name, tinygltf::Material& converted,
                                   std::optional<ConvertedImages>& images) {
    const auto e = mat.extensions.find("KHR_materials_pbrSpecularGlossiness");
    if (e == mat.extensions.end()) return mat;
    const std::string where = at + "/extensions/KHR_materials_pbrSpecularGlossiness";
    const tinygltf::Value& sg = e->second;
    if (!sg.IsObject()) fail(where, "must be an object");
    SpecularGlossiness f;
    if (sg.Has("diffuseFactor")) {
        const tinygltf::Value& v = sg.Get("diffuseFactor");
        if (!v.IsArray() || v.ArrayLen() != 4) fail(where + "/diffuseFactor", "needs 4 numbers");
        for (int k = 0; k < 4; ++k) {
            const double x = v.Get(k).IsNumber() ? v.Get(k).GetNumberAsDouble() : NAN;
            f.diffuse[k] = float(unit(x, where + "/diffuseFactor/" + std::to_string(k)));
        }
    }
    f.specular = extensionColour(sg, "specularFactor", vec3(1.0f), 1.0, where);
    f.glossiness = extensionNumber(sg, "glossinessFactor", 1.0, 0.0, 1.0, where);
    // The metallic-roughness parameters the file may also hold are a fallback for viewers
    // without the extension: replaced.
    converted = mat;
    tinygltf::PbrMetallicRoughness& pbr = converted.pbrMetallicRoughness;
    pbr = tinygltf::PbrMetallicRoughness();
    // The diffuse image alone, where the conversion is linear in the diffuse colour (a
    // specular of at most a dielectric's 0.04, metallic 0 whatever the diffuse): the base
    // colour's image, its factor the converted factors'. Otherwise the images are converted
    // texel by texel, the factors with them.
    const bool linear = perceived(f.specular) <= kDielectric;
    if (sg.Has("specularGlossinessTexture") || (sg.Has("diffuseTexture") && !linear)) {
        images = convertSpecularGlossiness(sg, at, name, f);
        return converted;
    }
    const MetallicRoughness mr = fromSpecularGlossiness(vec3(f.diffuse), f.specular);
    pbr.baseColorFactor = {mr.base.x, mr.base.y, mr.base.z, f.diffuse.w};
    pbr.metallicFactor = mr.metallic;
    pbr.roughnessFactor = 1.0 - f.glossiness;
    if (sg.Has("diffuseTexture"))
        pbr.baseColorTexture =
            extensionTextureInfo(sg, "diffuseTexture", where + "/diffuseTexture");
    return converted;
}

GltfReader::ConvertedImages GltfReader::convertSpecularGlossiness(const tinygltf::Value& sg,
                                                                  const std::string& at,
                                                                  const std::string& name,
                                                                  const SpecularGlossiness& f) {
    const std::string where = at + "/extensions/KHR_materials_pbrSpecularGlossiness";
    // Each image checked and opened as any texture is; the bake takes the larger of their
    // sizes, and the specular-glossiness image's coordinates, transform and sampler.
    struct Input {
        tinygltf::TextureInfo info;
        Texture picture;
        OpenedImage image;
    };
    std::optional<Input> diffuse, specular;
    const auto open = [&](const char* key, std::optional<Input>& input) {
        if (!sg.Has(key)) return;
        const std::string pointer = where + "/" + key;
        input.emplace();
        input->info = extensionTextureInfo(sg, key, pointer);
        input->picture = imageTexture(input->info, pointer, name + ": its " + key);
        Texture scratch;
        input->image = openImage(model_.textures[size_t(input->info.index)].source, scratch);
    };
    open("diffuseTexture", diffuse);
    open("specularGlossinessTexture", specular);
    const Input& lead = specular ? *specular : *diffuse;
    if (diffuse && specular &&
        (diffuse->info.texCoord != specular->info.texCoord ||
         diffuse->info.extensions != specular->info.extensions))
        warnOf(name, "KHR_materials_pbrSpecularGlossiness's diffuseTexture and "
                     "specularGlossinessTexture name different texture coordinates: both are "
                     "read through the specularGlossinessTexture's");
    int width = 0, height = 0;
    for (const std::optional<Input>* input : {&diffuse, &specular})
        if (*input) {
            width = std::max(width, (*input)->image.in->spec().width);
            height = std::max(height, (*input)->image.in->spec().height);
        }
    if (static_cast<long long>(width) * height > kMaxTexturePixels) {
        width = lead.image.in->spec().width;
        height = lead.image.in->spec().height;
    }
    std::optional<TexelRows> diffuseTexels, specularTexels;
    if (diffuse) diffuseTexels.emplace(*diffuse->image.in, width, height);
    if (specular) specularTexels.emplace(*specular->image.in, width, height);
    PngInMemory base(width, height, 4), metallicRoughness(width, height, 3);
    std::vector<std::uint8_t> baseRow(size_t(width) * 4), mrRow(size_t(width) * 3);
    for (int y = 0; y < height; ++y) {
        for (const auto& [texels, input] :
             {std::pair{&diffuseTexels, &diffuse}, std::pair{&specularTexels, &specular}})
            if (*texels && !(*texels)->seek(y))
                fail("/images/" +
                         std::to_string(model_.textures[size_t((*input)->info.index)].source),
                     "its pixels cannot be read: " + (*input)->image.in->geterror());
        convertRow(diffuseTexels ? &*diffuseTexels : nullptr,
                   specularTexels ? &*specularTexels : nullptr, f.diffuse, f.specular, f.glossiness,
                   baseRow, mrRow);
        base.row(y, baseRow);
        metallicRoughness.row(y, mrRow);
    }
    // Named as no file is, after the material ("model.gltf#material3-base.png").
    const std::string file = std::filesystem::absolute(path_).lexically_normal().string() +
                             "#material" + at.substr(at.rfind('/') + 1);
    ConvertedImages out{lead.picture, lead.picture};
    out.base.path = file + "-base.png";
    out.base.embedded = base.finish();
    out.metallicRoughness.path = file + "-metallicRoughness.png";
    out.metallicRoughness.embedded = metallicRoughness.finish();
    out.metallicRoughness.linear = true;
    return out;
}

} // namespace spw
