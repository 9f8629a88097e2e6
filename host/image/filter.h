// The pixel reconstruction filter: which footprint a sample adds to (host/image/film.cpp), as
// the scene file's `filter` names it (docs/scene-format.md).
#pragma once

namespace spw {

enum class FilterType { Box, Tent, Gaussian };
// The widest radius a scene may give (`filter: {width: ...}`), in pixels.
constexpr float kMaxFilterRadius = 16.0f;
struct Filter {
    FilterType type = FilterType::Box;
    float radius = 0.5f; // pixels; Box always covers its own pixel only
};

} // namespace spw
