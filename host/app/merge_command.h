// `spillway merge PART... -o IMAGE`: partial renders' exact sums (render --samples A:B --partial
// PART) added into the whole render's image, bit for bit the image one process would have made.
// Exit 0, 1 (the image cannot be written) or 2 (usage, or parts that do not make one render).
#pragma once

#include <string>
#include <vector>

namespace spw {

int mergeCommand(const std::vector<std::string>& args);

} // namespace spw
