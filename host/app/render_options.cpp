#include "host/app/render_options.h"

#include "host/app/usage_error.h"
#include "host/cpu/simd_shading.h"
#include "host/image/aov_film.h"
#include "host/image/image_io.h"
#include "host/image/output_file.h"
#include "host/loaders/gltf_loader.h"
#include "host/loaders/light_loader.h"
#include "host/pipeline/stage_chunks.h"
#include "host/scene/surface_models.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <iterator>
#include <sstream>

namespace spw {
namespace {

enum class Section { Render, Pipeline, Settings };

struct CliOption {
    const char* name;  // "--spp"
    const char* alias; // "-o", or nullptr
    const char* value; // the value's placeholder, or nullptr for a switch
    Section section;
    const char* help;
    double lo, hi; // the range of a numeric value
    void (*apply)(RenderOptions&, const CliOption&, const std::string& value);
};

long long integerValue(const CliOption& o, const std::string& v) {
    size_t used = 0;
    long long n = 0;
    try {
        n = std::stoll(v, &used);
    } catch (const std::exception&) {
        used = 0;
    }
    const std::string flag = o.name;
    if (used != v.size() || v.empty())
        throw UsageError(flag + " takes an integer, not '" + v + "'");
    if (n < (long long)o.lo || n > (long long)o.hi)
        throw UsageError(flag + " must be in [" + std::to_string((long long)o.lo) + ", " +
                         std::to_string((long long)o.hi) + "]");
    return n;
}

double numberValue(const CliOption& o, const std::string& v) {
    size_t used = 0;
    double x = 0;
    try {
        x = std::stod(v, &used);
    } catch (const std::exception&) {
        used = 0;
    }
    const std::string flag = o.name;
    if (used != v.size() || v.empty() || !std::isfinite(x))
        throw UsageError(flag + " takes a number, not '" + v + "'");
    if (x < o.lo || x > o.hi)
        throw UsageError(flag + " must be in [" + std::to_string(o.lo) + ", " +
                         std::to_string(o.hi) + "]");
    return x;
}

// A named choice through the library's parser, its error turned into a usage error.
template <class Parse> auto choice(const CliOption& o, const std::string& v, Parse parse) {
    try {
        return parse(v);
    } catch (const std::invalid_argument& e) {
        throw UsageError(std::string(o.name) + ": " + e.what());
    }
}

// One of `words` ("a|b|c"), or a usage error listing them.
std::string oneOf(const CliOption& o, const std::string& v, const std::string& words,
                  const std::string& listed) {
    std::istringstream in(words);
    for (std::string w; std::getline(in, w, '|');)
        if (v == w) return v;
    throw UsageError(std::string(o.name) + " takes " + listed + ", not '" + v + "'");
}

std::pair<int, int> sampleRange(const CliOption& o, const std::string& v) {
    const size_t colon = v.find(':');
    if (colon == std::string::npos)
        throw UsageError("--samples takes A:B (sample indices A <= s < B), not '" + v + "'");
    return {int(integerValue(o, v.substr(0, colon))), int(integerValue(o, v.substr(colon + 1)))};
}

using O = RenderOptions;
using C = CliOption;
using S = std::string;
constexpr double k24 = 1 << 24;

// The options that are not scene settings, in --help's order.
const std::vector<CliOption> kOwnOptions = {
    {"--output", "-o", "FILE", Section::Render,
     "image to write: .exr (linear float) or .png (8-bit sRGB); default: the scene's name "
     "with .exr, in the current folder",
     0, 0, [](O& r, const C&, const S& v) { r.output = v; }},
    {"--spp", nullptr, "N", Section::Render,
     "total samples per pixel (overrides sample base x iterations)", 1, k24,
     [](O& r, const C& o, const S& v) { r.config.spp = int(integerValue(o, v)); }},
    {"--backend", nullptr, "NAME", Section::Render,
     "auto (default: a real GPU where one is usable, else cpu), vulkan (the sorted deferred "
     "pipeline, shading as Vulkan compute; on a machine without a GPU, lavapipe's software "
     "emulation), cpu (the same, shading in C++) or reference (a plain depth-first path "
     "tracer on Embree)",
     0, 0, [](O& r, const C& o, const S& v) { r.config.backend = choice(o, v, parseBackend); }},
    {"--device", nullptr, "N|NAME", Section::Render,
     "the Vulkan device: its index in `spillway devices` or part of its name (default: the "
     "first usable one; with auto, a GPU, see `spillway devices`, or the device the Vulkan "
     "driver variables name)",
     0, 0, [](O& r, const C&, const S& v) { r.config.vulkan.device = v; }},
    {"--width", nullptr, "N", Section::Render,
     "image width in pixels (overrides the scene's; without --height the height keeps the "
     "scene's aspect ratio)",
     1, 1 << 15, [](O& r, const C& o, const S& v) { r.width = int(integerValue(o, v)); }},
    {"--height", nullptr, "N", Section::Render,
     "image height in pixels (overrides the scene's; without --width the width keeps the "
     "scene's aspect ratio)",
     1, 1 << 15, [](O& r, const C& o, const S& v) { r.height = int(integerValue(o, v)); }},
    {"--threads", nullptr, "N", Section::Render, "worker threads (default: every core)", 1, 1024,
     [](O& r, const C& o, const S& v) { r.config.threads = int(integerValue(o, v)); }},
    {"--sampler", nullptr, "TYPE", Section::Render,
     "Independent, Grid, Stratified or Sobol (overrides the scene's sampler)", 0, 0,
     [](O& r, const C&, const S& v) {
         r.sampler = parseSampler(v);
         if (!r.sampler)
             throw UsageError("--sampler takes Independent, Grid, Stratified or Sobol, not '" + v +
                              "'");
     }},
    {"--stats", nullptr, "FILE.json", Section::Render,
     "write render statistics (rays, stage seconds, ...) as JSON", 0, 0,
     [](O& r, const C&, const S& v) { r.statsPath = v; }},
    {"--quiet", nullptr, nullptr, Section::Render, "no progress bar", 0, 0,
     [](O& r, const C&, const S&) { r.quiet = true; }},
    {"--progress", nullptr, "MODE", Section::Render,
     "auto (default: a bar on a terminal, nothing otherwise), bar, lines (a line per "
     "iteration, for logs) or none; --quiet is none",
     0, 0,
     [](O& r, const C& o, const S& v) {
         r.progress = oneOf(o, v, "auto|bar|lines|none", "auto, bar, lines or none");
     }},
    {"--error-csv", nullptr, "FILE.csv", Section::Render,
     "after every iteration, a row: seconds, spp, relMSE estimated from two half buffers and "
     "that estimate's standard error, and with --reference the compare metrics",
     0, 0, [](O& r, const C&, const S& v) { r.errorCsvPath = v; }},
    {"--error-map", nullptr, "FILE.exr", Section::Render,
     "at the end, the per-pixel relMSE estimate from two half buffers, per channel (the "
     "terms --error-csv averages): where the noise is",
     0, 0, [](O& r, const C&, const S& v) { r.errorMapPath = v; }},
    {"--aov", nullptr, "PASSES", Section::Render,
     "render passes as layers of the output EXR, named as Cycles names them: any of albedo "
     "(\"Denoising Albedo\": what the pixel shows, through mirrors and smooth glass), normal "
     "(\"Normal\", world space, +Y up), camera-normal (\"Camera Normal\", +Z toward the "
     "camera), depth (\"Depth\"), comma-separated or repeated",
     0, 0,
     [](O& r, const C& o, const S& v) {
         try {
             r.config.aovs |= parseAovList(v); // repeated, the passes add up
         } catch (const std::invalid_argument& e) {
             throw UsageError(std::string(o.name) + " " + v + ": " + e.what());
         }
     }},
    {"--environment", nullptr, "FILE|R,G,B", Section::Render,
     "light the scene from everywhere with this, in place of its own environment (a glTF "
     "file's default white one, or a scene file's Environment light): a lat-long image (.hdr, "
     ".exr, ...; row 0 straight up) or a constant radiance R,G,B, times --environment-strength",
     0, 0, [](O& r, const C&, const S& v) { r.environment = v; }},
    {"--environment-strength", nullptr, "X", Section::Render,
     "multiplies --environment's radiance (default 1)", 0, kMaxRadiance,
     [](O& r, const C& o, const S& v) { r.environmentStrength = numberValue(o, v); }},
    {"--reference", nullptr, "REF.exr", Section::Render, "the reference image for --error-csv", 0,
     0, [](O& r, const C&, const S& v) { r.referencePath = v; }},
    {"--time-limit", nullptr, "SECONDS", Section::Render,
     "stop after the iteration that crosses this render time", 1e-3, 1e9,
     [](O& r, const C& o, const S& v) { r.config.timeLimitSeconds = numberValue(o, v); }},
    {"--target-error", nullptr, "E", Section::Render,
     "stop after the first iteration whose relMSE over the pixels that hold noise (a flat "
     "background left out), estimated from two half buffers (--error-csv's "
     "subject_relmse_estimate), is at or below E",
     0, 1e9, [](O& r, const C& o, const S& v) { r.config.targetError = numberValue(o, v); }},
    {"--uniform", nullptr, nullptr, Section::Render,
     "with --target-error, every pixel takes every sample (by default the image's 8 x 8 tiles "
     "share them by their noise, which reaches the target sooner)",
     0, 0, [](O& r, const C&, const S&) { r.config.adaptiveToTarget = false; }},
    {"--checkpoint", nullptr, "FILE.exr", Section::Render,
     "write the render's exact state (an EXR of the image so far, with the film's sums bit "
     "for bit in extra channels) at the end, however the render stops, and every "
     "--checkpoint-interval SECONDS of rendering",
     0, 0, [](O& r, const C&, const S& v) { r.checkpointPath = v; }},
    {"--checkpoint-interval", nullptr, "SECONDS", Section::Render,
     "also write the checkpoint every this many seconds of rendering", 1e-3, 1e9,
     [](O& r, const C& o, const S& v) { r.checkpointInterval = numberValue(o, v); }},
    {"--resume", nullptr, "FILE.exr", Section::Render,
     "continue a checkpointed render (same scene and image settings; more --spp may be asked "
     "for) to the image it would have made uninterrupted; checkpoints go back to FILE unless "
     "--checkpoint names another",
     0, 0, [](O& r, const C&, const S& v) { r.resumePath = v; }},
    {"--samples", nullptr, "A:B", Section::Render,
     "a partial render: only sample indices A <= s < B of the --spp N render (A and B on "
     "iteration boundaries), written with --partial",
     0, k24, [](O& r, const C& o, const S& v) { r.config.sampleRange = sampleRange(o, v); }},
    {"--partial", nullptr, "PART.exr", Section::Render,
     "where a partial render's exact sums go, for `spillway merge`", 0, 0,
     [](O& r, const C&, const S& v) { r.partialPath = v; }},
    {"--preview", nullptr, nullptr, Section::Render,
     "a window showing the image as iterations complete (+/- exposure, 0 reset; closing it, "
     "Esc or q stop the render as Ctrl-C does, but exit 0); without a display: exit 2 before "
     "rendering",
     0, 0, [](O& r, const C&, const S&) { r.preview = true; }},
    {"--texture-filter", nullptr, "F", Section::Render,
     "cone (default: lookups read the MIP levels each hit's ray-cone footprint needs, "
     "trilinear) or finest (always the finest level)",
     0, 0,
     [](O& r, const C& o, const S& v) {
         r.config.textureFilter = choice(o, v, parseTextureFilter);
     }},
    {"--spill-dir", nullptr, "DIR", Section::Pipeline,
     "where spilled batches and tiled copies of large textures go, as unnamed files (default: "
     "the system temp folder)",
     0, 0, [](O& r, const C&, const S& v) { r.config.pipeline.spillDir = v; }},
    {"--ray-sort", nullptr, "MODE", Section::Pipeline,
     "auto (sort only where it measures faster), morton, median or off", 0, 0,
     [](O& r, const C& o, const S& v) {
         r.config.pipeline.raySort = choice(o, v, parseRaySortMode);
     }},
    {"--hit-sort", nullptr, "MODE", Section::Pipeline,
     "sort hits by (shader, object, texture order) before shading: auto (default: for vulkan "
     "always, for cpu where the scene has image textures, by shader alone unless the images "
     "outgrow the texture cache), on or off",
     0, 0,
     [](O& r, const C& o, const S& v) {
         r.config.pipeline.hitSort = choice(o, v, parseHitSortMode);
     }},
    {"--shading", nullptr, "MODE", Section::Pipeline,
     "sorted (default: one dispatch per shader range, one kernel per surface model) or "
     "megakernel (unsorted hits, one uber-shader switching per hit)",
     0, 0,
     [](O& r, const C& o, const S& v) {
         r.config.pipeline.shading = choice(o, v, parseShadingMode);
     }},
    {"--ray-format", nullptr, "F", Section::Pipeline,
     "compact (34-byte rays, default) or full (50 bytes, every bit kept)", 0, 0,
     [](O& r, const C& o, const S& v) {
         r.config.pipeline.rayFormat = choice(o, v, parseRayFormat);
     }},
    {"--stages", nullptr, "MODE", Section::Pipeline,
     "fused (default; cpu: hit setup, shade, shadow, accumulate and bin run chunk by chunk "
     "of {chunk} hits, in cache; vulkan: shadow, accumulate and bin, after the device shaded the "
     "batch) or separate (each stage over the whole batch in turn)",
     0, 0,
     [](O& r, const C& o, const S& v) {
         r.config.pipeline.fuseStages =
             oneOf(o, v, "fused|separate", "fused or separate") == "fused";
     }},
    {"--simd-shading", nullptr, "on|off", Section::Pipeline,
     "cpu: shade the hits of {wide models} 4, 8 or 16 at a time in SIMD registers (default "
     "on), and filter runs of 8-bit texture lookups so; the image is the same either way",
     0, 0,
     [](O& r, const C& o, const S& v) {
         r.config.pipeline.simdShading = oneOf(o, v, "on|off", "on or off") == "on";
     }},
};

// The options that override a scene setting: one per settings-table entry with a flag.
const std::vector<CliOption>& settingOptions() {
    static const std::vector<CliOption> options = [] {
        std::vector<CliOption> o;
        for (const SettingSpec& s : settingsTable()) {
            if (!s.flag) continue;
            o.push_back({s.flag, nullptr, s.integer ? "N" : "X", Section::Settings, s.help, s.lo,
                         s.hi, [](O& r, const C& opt, const S& v) {
                             const SettingSpec* spec = settingForFlag(opt.name);
                             r.settings.emplace_back(spec, spec->integer
                                                               ? double(integerValue(opt, v))
                                                               : numberValue(opt, v));
                         }});
        }
        return o;
    }();
    return options;
}

const CliOption* findOption(const std::string& arg) {
    for (const auto* table : {&kOwnOptions, &settingOptions()})
        for (const CliOption& o : *table)
            if (arg == o.name || (o.alias && arg == o.alias)) return &o;
    return nullptr;
}

void checkAliases(const RenderOptions& r);

// How the options go together, checked before any work so that a mistake costs no render.
void checkRelations(RenderOptions& r) {
    if (r.scenePath.empty()) throw UsageError("render needs a scene file");
    if (r.environmentStrength && r.environment.empty())
        throw UsageError("--environment-strength scales --environment, which is not given");
    if (r.output.empty()) r.output = std::filesystem::path(r.scenePath).stem().string() + ".exr";
    if (!isSupportedOutput(r.output))
        throw UsageError("output '" + r.output + "' must end in .exr or .png");
    if (r.quiet) r.progress = "none";
    if (!r.errorMapPath.empty() && !isExrPath(r.errorMapPath))
        throw UsageError("--error-map '" + r.errorMapPath +
                         "' must be a file name ending in .exr (a name, then .exr): it holds "
                         "linear values, not colours");
    if (r.config.aovs != 0) {
        if (!isExrPath(r.output))
            throw UsageError("--aov writes layers of an EXR: the output '" + r.output +
                             "' must end in .exr");
        if (!r.checkpointPath.empty() || !r.resumePath.empty() || !r.partialPath.empty())
            throw UsageError("--aov does not go with --checkpoint, --resume or --partial yet: "
                             "checkpoints do not keep the passes");
    }
    if (!r.referencePath.empty() && r.errorCsvPath.empty())
        throw UsageError("--reference goes with --error-csv");
    if (!r.partialPath.empty() && !r.config.sampleRange)
        throw UsageError("--partial goes with --samples A:B");
    if (r.config.sampleRange && r.partialPath.empty())
        throw UsageError("--samples A:B goes with --partial PART.exr, where its sums go");
    if (!r.partialPath.empty()) {
        if (!r.checkpointPath.empty())
            throw UsageError("--partial is the render's checkpoint: give it or --checkpoint");
        r.checkpointPath = r.partialPath; // a partial is the checkpoint of its samples
    }
    if (!r.resumePath.empty() && r.checkpointPath.empty()) r.checkpointPath = r.resumePath;
    if (r.checkpointInterval > 0 && r.checkpointPath.empty())
        throw UsageError("--checkpoint-interval goes with --checkpoint");
    if (!r.checkpointPath.empty()) {
        std::string ext = std::filesystem::path(r.checkpointPath).extension().string();
        for (char& c : ext)
            c = char(std::tolower(static_cast<unsigned char>(c)));
        if (ext != ".exr")
            throw UsageError("checkpoint '" + r.checkpointPath + "' must end in .exr");
    }
    checkAliases(r);
}

// Outputs that name one file, or an output that names an input, would destroy one with the
// other: refused before any work, naming both. (--resume's file is the checkpoint's by design.)
void checkAliases(const RenderOptions& r) {
    struct Named {
        std::string what;
        const std::string* path;
    };
    const std::string checkpoint = !r.partialPath.empty() ? "--partial"
                                   : !r.resumePath.empty() && r.checkpointPath == r.resumePath
                                       ? "--resume"
                                       : "--checkpoint";
    const Named outputs[] = {{"-o", &r.output},
                             {"--stats", &r.statsPath},
                             {"--error-csv", &r.errorCsvPath},
                             {"--error-map", &r.errorMapPath},
                             {checkpoint, &r.checkpointPath}};
    const Named inputs[] = {{"the scene", &r.scenePath},
                            {"--reference", &r.referencePath},
                            {"--resume", &r.resumePath}};
    auto refuse = [](const Named& a, const Named& b) {
        throw UsageError(a.what + " and " + b.what + " name the same file '" + *a.path +
                         "': one would destroy the other");
    };
    for (size_t i = 0; i < std::size(outputs); ++i) {
        if (outputs[i].path->empty()) continue;
        for (size_t j = i + 1; j < std::size(outputs); ++j)
            if (!outputs[j].path->empty() && sameFile(*outputs[i].path, *outputs[j].path))
                refuse(outputs[i], outputs[j]);
        for (const Named& in : inputs) {
            const bool resumed = in.path == &r.resumePath && outputs[i].path == &r.checkpointPath;
            if (!in.path->empty() && !resumed && sameFile(*outputs[i].path, *in.path))
                refuse(outputs[i], in);
        }
    }
}

// `text` wrapped to lines of at most `width` characters, each after `indent`.
std::string wrap(const std::string& text, size_t indent, size_t width) {
    std::istringstream words(text);
    std::string out, line;
    for (std::string w; words >> w;) {
        if (!line.empty() && line.size() + 1 + w.size() > width) {
            out += line + "\n" + std::string(indent, ' ');
            line.clear();
        }
        line += (line.empty() ? "" : " ") + w;
    }
    return out + line + "\n";
}

// A help text with its placeholders filled from what they describe: {chunk}, the fused stages'
// chunk of hits; {wide models}, the surface models with a SIMD twin.
std::string filled(std::string help) {
    std::string wide;
    std::vector<std::string> names;
    for (uint model = 0; model < kModelCount; ++model)
        if (kWideTwins[model].shade) names.push_back(surfaceModel(model)->name);
    for (size_t k = 0; k < names.size(); ++k)
        wide += (k == 0 ? "" : k + 1 == names.size() ? " and " : ", ") + names[k];
    for (const auto& [key, value] :
         {std::pair<std::string, std::string>{"{chunk}", std::to_string(kChunk)},
          {"{wide models}", wide}})
        for (size_t at; (at = help.find(key)) != std::string::npos;)
            help.replace(at, key.size(), value);
    return help;
}

std::string helpSection(Section section) {
    constexpr size_t column = 24, width = 94;
    std::string out;
    for (const auto* table : {&kOwnOptions, &settingOptions()})
        for (const CliOption& o : *table) {
            if (o.section != section) continue;
            std::string head = "  ";
            if (o.alias) head += std::string(o.alias) + ", ";
            head += o.name;
            if (o.value) head += std::string(" ") + o.value;
            std::string help = filled(o.help);
            if (section == Section::Settings)
                help += std::string(" (settings: ") + settingForFlag(o.name)->key + ")";
            head += head.size() < column ? std::string(column - head.size(), ' ')
                                         : "\n" + std::string(column, ' ');
            out += head + wrap(help, column, width - column);
        }
    return out;
}

} // namespace

RenderOptions parseRenderOptions(const std::vector<std::string>& args) {
    RenderOptions r;
    for (size_t i = 0; i < args.size(); ++i) {
        const std::string& a = args[i];
        if (a == "-h" || a == "--help") {
            r.help = true;
            return r;
        }
        if (const CliOption* o = findOption(a)) {
            std::string v;
            if (o->value) {
                if (i + 1 >= args.size()) throw UsageError(a + " needs a value");
                v = args[++i];
                // An empty file name (--resume "", an unset variable) is a mistake, never "none".
                const std::string placeholder = o->value;
                if (v.empty() &&
                    (placeholder == "FILE" || placeholder.find('.') != std::string::npos))
                    throw UsageError(a + " needs a file name, not an empty string");
            }
            o->apply(r, *o, v);
        } else if (!a.empty() && a[0] == '-')
            throw UsageError("unknown option '" + a + "'");
        else if (r.scenePath.empty())
            r.scenePath = a;
        else
            throw UsageError("more than one scene given ('" + r.scenePath + "', '" + a + "')");
    }
    checkRelations(r);
    return r;
}

std::string renderOptionsHelp() {
    return "render options:\n" + helpSection(Section::Render) +
           "\nsorted pipeline options (cpu and vulkan backends):\n" +
           helpSection(Section::Pipeline) +
           "\nscene settings (docs/scene-format.md, `settings:`), overridden:\n" +
           helpSection(Section::Settings);
}

namespace {

// "R,G,B" as three numbers, or nothing.
std::optional<glm::dvec3> rgbTriple(const std::string& v) {
    std::vector<std::string> parts(1);
    for (char ch : v) {
        if (ch == ',')
            parts.emplace_back();
        else
            parts.back().push_back(ch);
    }
    if (parts.size() != 3) return std::nullopt;
    glm::dvec3 rgb;
    for (int c = 0; c < 3; ++c) {
        size_t used = 0;
        try {
            rgb[c] = std::stod(parts[size_t(c)], &used);
        } catch (const std::exception&) {
            return std::nullopt;
        }
        if (used != parts[size_t(c)].size()) return std::nullopt;
    }
    return rgb;
}

// --environment's value: a constant where it is R,G,B, else an image's path; either times
// --environment-strength.
Environment commandLineEnvironment(const RenderOptions& options) {
    const double strength = options.environmentStrength.value_or(1.0);
    const std::string& v = options.environment;
    const std::optional<glm::dvec3> rgb = rgbTriple(v);
    if (!rgb) {
        if (v.find(',') != std::string::npos && !std::filesystem::exists(v))
            throw UsageError("--environment takes an image or R,G,B (three numbers), not '" + v +
                             "'");
        try {
            return scene_file::environmentMap(v, vec3(float(strength)));
        } catch (const std::exception& e) {
            throw UsageError(std::string("--environment: ") + e.what());
        }
    }
    Environment env;
    for (int c = 0; c < 3; ++c) {
        const double radiance = (*rgb)[c] * strength;
        if (!((*rgb)[c] >= 0.0 && radiance <= kMaxRadiance))
            throw UsageError(
                "--environment " + v +
                ": each radiance, times --environment-strength, must lie in 0 .. 1e20");
        env.radiance[c] = float(radiance);
    }
    return env;
}

} // namespace

void applyOverrides(const RenderOptions& options, Scene& scene) {
    applySettingOverrides(scene.settings, options.settings);
    if (!options.environment.empty()) {
        scene.environment = commandLineEnvironment(options);
        // The loader's word that it added an environment no longer holds: this one replaced it.
        std::vector<std::string>& w = scene.warnings;
        w.erase(std::remove_if(w.begin(), w.end(),
                               [](const std::string& s) {
                                   return s.find(kAddedEnvironmentNote) != std::string::npos;
                               }),
                w.end());
    }
    if (options.sampler) scene.sampler = *options.sampler;
    ImageSettings& img = scene.image;
    const double aspect = double(img.width) / double(img.height);
    if (options.width && options.height) {
        img.width = *options.width, img.height = *options.height;
    } else if (options.width) {
        img.width = *options.width;
        img.height = std::max(1, int(std::lround(*options.width / aspect)));
    } else if (options.height) {
        img.height = *options.height;
        img.width = std::max(1, int(std::lround(*options.height * aspect)));
    }
    img.width = std::clamp(img.width, 1, 1 << 15), img.height = std::clamp(img.height, 1, 1 << 15);
    if ((long long)img.width * img.height > kMaxImagePixels)
        throw UsageError("--width and --height: an image of " + std::to_string(img.width) + "x" +
                         std::to_string(img.height) + " pixels is larger than the " +
                         std::to_string(kMaxImagePixels) + " pixels Spillway renders");
    if ((unsigned long long)img.width * img.height * img.samplesPerIteration() > 0xFFFFFFFFull)
        throw UsageError("--width x --height x the scene's sample base^2 exceeds 2^32 - 1 samples "
                         "per iteration");
}

} // namespace spw
