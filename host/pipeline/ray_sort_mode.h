#pragma once

#include <string>

namespace spw {

enum class RaySortMode { Auto, Morton, Median, Off };
RaySortMode parseRaySortMode(const std::string& name); // throws std::invalid_argument
const char* raySortName(RaySortMode mode);

} // namespace spw
