// The settings table (host/scene/settings_table.h) is the one place a scene setting is declared:
// docs/scene-format.md documents every entry with the table's default and range, the loader
// enforces each range at both ends, and each flag of the CLI overrides its setting.
#include "host/app/render_options.h"
#include "host/app/usage.h"
#include "host/app/usage_error.h"
#include "host/loaders/scene_loader.h"
#include "host/scene/settings_table.h"
#include "test_util.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <map>
#include <sstream>

namespace spw::test {
namespace {

// docs/scene-format.md's `## settings` table: key -> (default, range) cells.
std::map<std::string, std::pair<std::string, std::string>> documentedSettings() {
    std::istringstream docs(readFile(sourceDir() + "/docs/scene-format.md"));
    std::map<std::string, std::pair<std::string, std::string>> rows;
    bool inSettings = false;
    for (std::string line; std::getline(docs, line);) {
        if (line.rfind("## ", 0) == 0) inSettings = line == "## settings";
        if (!inSettings || line.rfind("| `", 0) != 0) continue;
        std::vector<std::string> cells;
        std::istringstream row(line.substr(1));
        for (std::string cell; std::getline(row, cell, '|');)
            cells.push_back(cell.substr(1, cell.size() - 2)); // " x " -> "x"
        if (cells.size() < 3) continue;
        rows[cells[0].substr(1, cells[0].size() - 2)] = {cells[1], cells[2]}; // `key` -> key
    }
    return rows;
}

std::string formatDefault(double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%g", v);
    return buf;
}

TEST(SettingsTable, EveryEntryIsDocumentedWithItsDefaultAndRange) {
    const auto documented = documentedSettings();
    ASSERT_FALSE(documented.empty());
    const Settings defaults;
    for (const SettingSpec& spec : settingsTable()) {
        const auto it = documented.find(spec.key);
        ASSERT_NE(it, documented.end()) << spec.key << " is not in docs/scene-format.md";
        const std::string value = formatDefault(spec.get(defaults));
        EXPECT_EQ(it->second.first.substr(0, value.size()), value) << spec.key;
        EXPECT_EQ(it->second.second, spec.docsRange) << spec.key;
    }
    EXPECT_EQ(documented.size(), settingsTable().size())
        << "the docs list a setting the table lacks";
}

std::string sceneWith(const TempDir& dir, const std::string& key, double value) {
    std::ostringstream text;
    text.precision(17);
    text << "settings: {" << key << ": " << value << "}\n";
    return dir.write("s.yaml", text.str());
}

TEST(SettingsTable, TheLoaderTakesEachEndOfEachRangeAndRefusesBeyondIt) {
    TempDir dir;
    for (const SettingSpec& spec : settingsTable()) {
        for (double edge : {spec.lo, spec.hi}) {
            const Scene scene = loadScene(sceneWith(dir, spec.key, edge));
            const double expected = spec.single ? double(float(edge)) : edge; // float settings
            EXPECT_EQ(spec.get(scene.settings), expected) << spec.key << " = " << edge;
        }
        const double beyond = spec.hi + (spec.integer ? 1 : spec.hi);
        try {
            loadScene(sceneWith(dir, spec.key, beyond));
            ADD_FAILURE() << spec.key << " = " << beyond << " was accepted";
        } catch (const SceneError& e) {
            EXPECT_NE(std::string(e.what()).find(std::string(spec.key) + " must be in"),
                      std::string::npos)
                << e.what();
            EXPECT_EQ(e.line(), 1) << e.what();
        }
    }
}

TEST(SettingsTable, EachFlagOverridesItsSettingOnceTheSceneIsLoaded) {
    TempDir dir;
    const std::string path = smallCornellBox(dir, 8, 8);
    int flags = 0;
    for (const SettingSpec& spec : settingsTable()) {
        if (!spec.flag) continue;
        ++flags;
        std::ostringstream value;
        value.precision(17);
        value << spec.lo;
        const RenderOptions o = parseRenderOptions({path, spec.flag, value.str()});
        Scene scene = loadScene(path);
        applyOverrides(o, scene);
        EXPECT_EQ(spec.get(scene.settings), spec.lo) << spec.flag;
        EXPECT_NE(usageText().find(spec.flag), std::string::npos) << spec.flag;
        std::ostringstream beyond;
        beyond.precision(17);
        beyond << spec.hi * 2 + 1;
        EXPECT_THROW(parseRenderOptions({path, spec.flag, beyond.str()}), UsageError) << spec.flag;
    }
    EXPECT_EQ(flags, 6); // seed, bin exponent, memory budget, texture cache, adaptive x2
}

} // namespace
} // namespace spw::test
