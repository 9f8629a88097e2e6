#include "host/scene/settings_table.h"

namespace spw {

double SettingSpec::get(const Settings& s) const {
    if (real) return s.*real;
    if (whole) return s.*whole;
    if (single) return s.*single;
    return s.*u32;
}

void SettingSpec::set(Settings& s, double v) const {
    if (real)
        s.*real = v;
    else if (whole)
        s.*whole = int(v);
    else if (single)
        s.*single = float(v);
    else
        s.*u32 = std::uint32_t(v);
}

const std::vector<SettingSpec>& settingsTable() {
    static const std::vector<SettingSpec> table = [] {
        std::vector<SettingSpec> t;
        auto add = [&](SettingSpec spec) { t.push_back(spec); };
        const double maxDepth = kMaxDepth, k24 = 1 << 24, k20 = 1 << 20;
        add({"min depth", nullptr, true, 0, maxDepth, "integer 0 … 32767",
             "bounces before Russian roulette may end a path", nullptr, &Settings::minDepth});
        add({"max depth", nullptr, true, 0, maxDepth, "integer 0 … 32767", "most bounces", nullptr,
             &Settings::maxDepth});
        add({"threshold", nullptr, false, 0, 1e30, "≥ 0", "Russian roulette's throughput threshold",
             nullptr, nullptr, &Settings::threshold});
        add({"bucket size", nullptr, true, 1, 4096, "integer 1 … 4096",
             "edge in pixels of the camera tiles", nullptr, &Settings::bucketSize});
        add({"shading size", nullptr, true, 1, k24, "integer 1 … 2^24",
             "most hits in one shading task", nullptr, &Settings::shadingSize});
        add({"bin exponent", "--bin-exponent", true, 4, 24, "integer 4 … 24",
             "a directional bin becomes a batch at 2^E rays", nullptr, &Settings::binExponent});
        add({"memory budget", "--memory-budget", false, 1.0 / 1024, k20, "1/1024 … 2^20 MiB",
             "MiB of RAM for rays waiting in bins and queued batches; the rest spills to disk",
             &Settings::memoryBudgetMiB});
        add({"texture cache", "--texture-cache", false, 1, k20, "1 … 2^20 MiB",
             "MiB of the texture system's tile cache", &Settings::textureCacheMiB});
        add({"seed", "--seed", true, 0, 4294967295.0, "integer 0 … 2^32 − 1", "the random seed",
             nullptr, nullptr, nullptr, &Settings::seed});
        add({"adaptive threshold", "--adaptive-threshold", false, 0, 1e9, "0 … 1e9",
             "adaptive sampling's relative RMS error per 8x8 tile (0: off)",
             &Settings::adaptiveThreshold});
        add({"adaptive min samples", "--adaptive-min-spp", true, 2, k24, "integer 2 … 2^24",
             "samples every pixel takes before its tile may stop", nullptr,
             &Settings::adaptiveMinSamples});
        return t;
    }();
    return table;
}

const SettingSpec* settingForFlag(const std::string& flag) {
    for (const SettingSpec& s : settingsTable())
        if (s.flag && flag == s.flag) return &s;
    return nullptr;
}

void applySettingOverrides(Settings& settings, const SettingOverrides& overrides) {
    for (const auto& [spec, value] : overrides)
        spec->set(settings, value);
}

} // namespace spw
