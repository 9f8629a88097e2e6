// Images in and out through OpenImageIO: linear float EXR, or 8-bit sRGB PNG, by extension.
#pragma once

#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

namespace spw {

struct ImageRGB {
    int width = 0, height = 0;
    std::vector<float> rgb; // linear, row-major, 3 floats a pixel
};

// The sRGB transfer function, decoded: 8-bit images and textures are linearised with it.
inline float srgbToLinear(float c) {
    return c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f);
}

// True for the extensions writeImage understands (.exr, .png; any case).
bool isSupportedOutput(const std::string& path);
// Throws std::runtime_error naming the path when the file cannot be written.
void writeImage(const std::string& path, const ImageRGB& image);
// Reads any image OpenImageIO reads; 8-bit sRGB data are linearised. Throws on failure.
ImageRGB readImage(const std::string& path);

} // namespace spw
