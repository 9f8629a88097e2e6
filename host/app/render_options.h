// `spillway render`'s command line as one table: each option's name, value, help and range, and
// what it sets. The parser, `--help` and the README's command check
// (scripts/check_readme_commands.py) all read it. Options that override a scene setting come from
// the settings table (host/scene/settings_table.h), with the loader's ranges.
#pragma once

#include "host/backend/render_config.h"
#include "host/scene/scene.h"
#include "host/scene/settings_table.h"

#include <optional>
#include <string>
#include <vector>

namespace spw {

// Everything `spillway render` was told.
struct RenderOptions {
    std::string scenePath;
    std::string output; // default: the scene's name with .exr
    std::string statsPath, errorCsvPath, errorMapPath, referencePath;
    std::string checkpointPath, resumePath, partialPath;
    double checkpointInterval = 0;
    std::optional<SamplerType> sampler;        // --sampler: replaces the scene's
    std::optional<int> width, height;          // --width, --height: replace the image's size
    std::string environment;                   // --environment FILE|R,G,B: replaces the scene's
    std::optional<double> environmentStrength; // --environment-strength
    SettingOverrides settings;                 // --seed, --bin-exponent, ...: replace the scene's
    bool preview = false;
    std::string progress = "auto"; // auto | bar | lines | none (also after --quiet)
    bool quiet = false;
    bool help = false; // -h, --help: print the usage and do nothing else
    RenderConfig config = [] {
        RenderConfig c;
        c.backend = BackendKind::Auto; // the library's default is cpu; the CLI's is auto
        return c;
    }();
};

// Parses the arguments after `render`, and checks how options go together (--partial with
// --samples, an .exr checkpoint, ...). Throws UsageError.
RenderOptions parseRenderOptions(const std::vector<std::string>& args);

// The options part of `spillway --help`, made from the table.
std::string renderOptionsHelp();

// The scene's settings, sampler, image size and environment with the command line's overrides:
// applied once, right after loading, so that the scene then holds what the render uses. Throws
// UsageError for a size whose samples per iteration pass 2^32 - 1, or an environment that cannot
// be read.
void applyOverrides(const RenderOptions& options, Scene& scene);

} // namespace spw
