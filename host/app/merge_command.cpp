#include "host/app/merge_command.h"

#include "host/app/usage_error.h"
#include "host/image/film.h"
#include "host/image/image_io.h"
#include "host/image/output_file.h"
#include "host/render/checkpoint.h"

#include <cstdio>
#include <stdexcept>
#include <utility>

namespace spw {

int mergeCommand(const std::vector<std::string>& args) {
    std::string output;
    std::vector<std::string> parts;
    for (size_t i = 0; i < args.size(); ++i) {
        if (args[i] == "-o" || args[i] == "--output") {
            if (i + 1 >= args.size()) throw UsageError(args[i] + " needs a value");
            output = args[++i];
        } else if (!args[i].empty() && args[i][0] == '-') {
            throw UsageError("unknown merge option '" + args[i] + "'");
        } else {
            parts.push_back(args[i]);
        }
    }
    if (parts.empty()) throw UsageError("merge needs partial renders (render --partial)");
    if (output.empty()) throw UsageError("merge needs -o IMAGE");
    if (!isSupportedOutput(output))
        throw UsageError("output '" + output + "' must end in .exr or .png");
    for (const std::string& p : parts)
        if (sameFile(output, p))
            throw UsageError("-o and the partial render '" + p +
                             "' name the same file: the image would destroy the part");
    checkWritable(output);
    std::vector<std::pair<std::string, Checkpoint>> partials;
    for (const std::string& p : parts) {
        try {
            partials.emplace_back(p, readCheckpoint(p));
        } catch (const std::exception& e) {
            throw UsageError(std::string("merge: ") + e.what());
        }
    }
    Checkpoint whole;
    try {
        whole = mergePartials(partials);
    } catch (const std::invalid_argument& e) {
        throw UsageError(std::string("merge: ") + e.what());
    }
    OutputFile image(output);
    const std::vector<unsigned char> bytes =
        encodeImage(output, {whole.key.width, whole.key.height, Film::imageOf(whole.film)});
    image.write(bytes.data(), bytes.size());
    image.flush();
    image.commit();
    std::fprintf(stderr, "spillway: merged %zu partial renders: %d spp\n", partials.size(),
                 whole.iterations * whole.key.sampleBase * whole.key.sampleBase);
    return 0;
}

} // namespace spw
