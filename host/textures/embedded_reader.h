// OpenImageIO's reader of an image embedded in a scene file (Texture::embedded): the loader
// reads its header through one, the texture cache and tiled copies its pixels. An image in a
// glTF buffer is read from the file a piece at a time (pread), so that its encoded bytes are
// never held whole in memory, whatever its size; one written in the file's JSON as a data: URI,
// from its base64 text, decoded as it is read (a JPEG's decoded while its reader is open:
// OpenImageIO's JPEG reader reads only from memory or a FILE*); an image in memory from its bytes.
#pragma once

#include "host/scene/scene.h"

#include <OpenImageIO/filesystem.h>

#include <memory>

namespace spw {

// A reader of `image` for OpenImageIO (through the "oiio:ioproxy" attribute). Throws
// std::runtime_error naming the file where it cannot be opened or no longer holds the image's
// bytes (truncated since it was loaded).
std::unique_ptr<OIIO::Filesystem::IOProxy> embeddedReader(const EmbeddedImage& image);

} // namespace spw
