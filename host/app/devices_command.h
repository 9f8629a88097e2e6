// `spillway devices`: the Vulkan devices, their drivers, whether each is usable, and which one
// `--backend auto` takes. Exit 0, or 1 where there is no Vulkan device at all.
#pragma once

#include <string>
#include <vector>

namespace spw {

int devicesCommand(const std::vector<std::string>& args);

} // namespace spw
