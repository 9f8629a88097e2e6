// The image writer: an image encoded a block of rows at a time into its output file reads back
// exactly, in each format and on either side of the size where EXR's compression changes, and a
// destination that cannot seek (a FIFO) gets the same file.
#include "host/image/image_io.h"
#include "host/image/output_file.h"
#include "test_util.h"

#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>

#include <sys/stat.h>

#include <fstream>
#include <thread>

namespace spw {
namespace {

using test::TempDir;

// A value per pixel and channel that no two neighbours share, with every float bit in use.
float valueAt(int x, int y, int c) {
    return float(x * 3 + c) * 1.000123f + float(y) * 0.37f + 1e-3f * float((x ^ y) & 255);
}

void writeRows(const std::string& path, int width, int height) {
    OutputFile file(path);
    writeImageRows(file, path, width, height, [&](int y0, int y1, float* rgb) {
        for (int y = y0; y < y1; ++y)
            for (int x = 0; x < width; ++x)
                for (int c = 0; c < 3; ++c)
                    *rgb++ = valueAt(x, y, c);
    });
    file.commit();
}

std::string compressionOf(const std::string& path) {
    auto in = OIIO::ImageInput::open(path);
    return in ? in->spec().get_string_attribute("compression") : "unreadable";
}

TEST(ImageWriter, RowBlocksReadBackExactlyAndLargeExrsAreRle) {
    TempDir dir;
    // 2048 x 2048 is the largest zip image (2^22 pixels); one row more is RLE. Both take several
    // blocks of rows.
    for (const int height : {2048, 2049}) {
        const std::string path = dir.file("i" + std::to_string(height) + ".exr");
        writeRows(path, 2048, height);
        EXPECT_EQ(compressionOf(path), height == 2048 ? "zip" : "rle");
        const ImageRGB back = readImage(path);
        ASSERT_EQ(back.width, 2048);
        ASSERT_EQ(back.height, height);
        size_t wrong = 0;
        for (int y = 0; y < height; ++y)
            for (int x = 0; x < 2048; ++x)
                for (int c = 0; c < 3; ++c)
                    wrong += back.rgb[(size_t(y) * 2048 + size_t(x)) * 3 + size_t(c)] !=
                             valueAt(x, y, c);
        EXPECT_EQ(wrong, 0u) << height;
    }
    writeRows(dir.file("small.png"), 5, 3);
    const ImageRGB png = readImage(dir.file("small.png"));
    EXPECT_EQ(png.width, 5);
    EXPECT_EQ(png.height, 3);
}

TEST(ImageWriter, AFifoGetsTheSameImage) {
    TempDir dir;
    const std::string fifo = dir.file("fifo.exr"), copy = dir.file("copy.exr");
    ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
    std::thread reader([&] {
        std::ifstream in(fifo, std::ios::binary);
        std::ofstream out(copy, std::ios::binary);
        out << in.rdbuf();
    });
    writeRows(fifo, 64, 40);
    reader.join();
    const ImageRGB back = readImage(copy);
    ASSERT_EQ(back.width, 64);
    ASSERT_EQ(back.height, 40);
    EXPECT_EQ(back.rgb[(size_t(39) * 64 + 63) * 3 + 2], valueAt(63, 39, 2));
}

} // namespace
} // namespace spw
