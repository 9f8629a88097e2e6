#include "host/app/usage.h"

#include "host/app/render_options.h"

namespace spw {

std::string usageText() {
    return R"(Spillway: a breadth-first, sorted-deferred-shading path tracer.

usage:
  spillway render SCENE [options]   render a scene file (see docs/scene-format.md)
  spillway compare A B [options]    error metrics of image A against reference B
  spillway merge PART... -o IMAGE   add partial renders (--samples A:B --partial PART) that
                                    cover every sample once into the whole render's image,
                                    bit for bit the image one process would have made
  mpirun -np N spillway render SCENE [options]
                                    one render across N MPI ranks (hosts): every rank takes
                                    a share of each iteration's tiles, rank 0 writes the
                                    outputs; the image is the single process's, bit for bit
  spillway devices                  the Vulkan devices, their drivers, and which are usable
  spillway --help                   this text
  spillway --version                the version

)" + renderOptionsHelp() +
           R"(
Ctrl-C (SIGINT) or SIGTERM stops the render at the next batch boundary, writes the image of
every completed iteration (and --stats, --error-csv) and exits 130 or 143; a second one exits
at once, writing nothing.

exit status: 0 done; 1 runtime failure (disk, device, an output that cannot be written);
2 bad usage or scene error (printed as FILE:LINE: message). On any failure no output file
is written or changed, and no temporary file is left.
)";
}

} // namespace spw
