// The scene's `settings:` in one table: each setting's scene key, the command-line flag that
// overrides it (if any), its range, its default and its help. The scene loader, the CLI's parser,
// `--help` and the docs test (docs/scene-format.md's settings table) all read this one table, so a
// setting is added, or its range changed, in one line.
//
// A CLI override is applied once, right after the scene is loaded (applySettingOverrides): from
// then on the scene holds the render's settings, and nothing downstream asks where a value came
// from.
#pragma once

#include "host/scene/scene.h"

#include <string>
#include <utility>
#include <vector>

namespace spw {

struct SettingSpec {
    const char* key;                   // under `settings:` in the scene file
    const char* flag;                  // the CLI flag that overrides it, or nullptr
    bool integer;                      // an integer setting (else any number in the range)
    double lo, hi;                     // the accepted range, inclusive
    const char* docsRange;             // the range as docs/scene-format.md writes it
    const char* help;                  // one line for --help
    double Settings::*real = nullptr;  // where a number setting lives
    int Settings::*whole = nullptr;    // where an int setting lives
    float Settings::*single = nullptr; // where a float setting lives
    std::uint32_t Settings::*u32 = nullptr;

    double get(const Settings& s) const;
    void set(Settings& s, double v) const;
};

// Every setting, in the docs' order.
const std::vector<SettingSpec>& settingsTable();
// The setting a flag (e.g. "--seed") overrides, or nullptr.
const SettingSpec* settingForFlag(const std::string& flag);

// Values given on the command line, by setting, in the order given.
using SettingOverrides = std::vector<std::pair<const SettingSpec*, double>>;
void applySettingOverrides(Settings& settings, const SettingOverrides& overrides);

} // namespace spw
