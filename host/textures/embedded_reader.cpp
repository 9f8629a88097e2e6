#include "host/textures/embedded_reader.h"

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <stdexcept>

namespace spw {
namespace {

// `length` bytes at `offset` of an open file, as a read-only file of their own. pread keeps it
// safe for the cache's threads; read() and seek() move the proxy's own position.
class FileRangeReader final : public OIIO::Filesystem::IOProxy {
  public:
    // The bytes `image` stores in its file (its base64 text where it has one).
    FileRangeReader(const EmbeddedImage& image)
        : IOProxy(image.file, Read), offset_(std::int64_t(image.offset)),
          length_(std::int64_t(image.stored())) {
        fd_ = ::open(image.file.c_str(), O_RDONLY | O_CLOEXEC);
        struct stat st {};
        if (fd_ < 0 || ::fstat(fd_, &st) != 0) {
            const std::string why = std::strerror(errno);
            if (fd_ >= 0) ::close(fd_);
            throw std::runtime_error("cannot open '" + image.file + "': " + why);
        }
        if (std::uint64_t(st.st_size) < image.offset + image.stored()) {
            ::close(fd_);
            throw std::runtime_error("'" + image.file + "' no longer holds its embedded image (" +
                                     std::to_string(image.length) + " bytes at " +
                                     std::to_string(image.offset) + "): it is " +
                                     std::to_string(st.st_size) + " bytes long");
        }
    }
    ~FileRangeReader() override { ::close(fd_); }
    const char* proxytype() const override { return "filerange"; }
    size_t size() const override { return size_t(length_); }
    size_t read(void* buf, size_t size) override {
        const size_t n = pread(buf, size, m_pos);
        m_pos += std::int64_t(n);
        return n;
    }
    size_t pread(void* buf, size_t size, int64_t offset) override {
        if (offset < 0 || offset >= length_) return 0;
        size = size_t(std::min<std::int64_t>(std::int64_t(size), length_ - offset));
        size_t done = 0;
        while (done < size) {
            const ssize_t n = ::pread(fd_, static_cast<char*>(buf) + done, size - done,
                                      offset_ + offset + std::int64_t(done));
            if (n < 0 && errno == EINTR) continue;
            if (n <= 0) break;
            done += size_t(n);
        }
        return done;
    }

  private:
    int fd_ = -1;
    std::int64_t offset_, length_;
};

// The values of base64's characters (RFC 4648's alphabet), -2 for the padding, -1 for the rest.
struct Base64Values {
    signed char value[256];
    Base64Values() {
        std::fill(std::begin(value), std::end(value), static_cast<signed char>(-1));
        const char* alphabet = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
        for (int i = 0; i < 64; ++i)
            value[static_cast<unsigned char>(alphabet[i])] = static_cast<signed char>(i);
        value[static_cast<unsigned char>('=')] = -2;
    }
};
const Base64Values kBase64;

// An image written out in its file as base64 text (a data: URI), decoded as it is read: byte k
// is in the 4 characters from 4 (k / 3), so any range is read from its own characters alone.
class Base64Reader final : public OIIO::Filesystem::IOProxy {
  public:
    explicit Base64Reader(const EmbeddedImage& image)
        : IOProxy(image.file, Read), text_(image), length_(std::int64_t(image.length)) {}
    const char* proxytype() const override { return "base64"; }
    size_t size() const override { return size_t(length_); }
    size_t read(void* buf, size_t size) override {
        const size_t n = pread(buf, size, m_pos);
        m_pos += std::int64_t(n);
        return n;
    }
    // A short count where the text is not base64 (the file changed since it was loaded).
    size_t pread(void* buf, size_t size, int64_t offset) override {
        if (offset < 0 || offset >= length_) return 0;
        size = size_t(std::min<std::int64_t>(std::int64_t(size), length_ - offset));
        auto* out = static_cast<unsigned char*>(buf);
        size_t done = 0;
        unsigned char chars[kChunk];
        while (done < size) {
            const std::int64_t at = offset + std::int64_t(done);
            const std::int64_t group = at / 3, skip = at % 3;
            const size_t groups =
                std::min<size_t>(kChunk / 4, (size - done + size_t(skip) + 2) / 3);
            const size_t got = text_.pread(chars, groups * 4, group * 4);
            for (size_t g = 0; g < got / 4 && done < size; ++g) {
                unsigned char bytes[3];
                const int n = decodeGroup(chars + 4 * g, bytes);
                for (int b = g == 0 ? int(skip) : 0; b < n && done < size; ++b)
                    out[done++] = bytes[b];
                if (n < 3) return done; // padding, or not base64
            }
            if (got < groups * 4) break;
        }
        return done;
    }

  private:
    static constexpr size_t kChunk = 64 * 1024;
    // Four characters into up to three bytes; how many (fewer at the padding, 0 if not base64).
    static int decodeGroup(const unsigned char* c, unsigned char* bytes) {
        const int a = kBase64.value[c[0]], b = kBase64.value[c[1]];
        const int d2 = kBase64.value[c[2]], d3 = kBase64.value[c[3]];
        if ((a | b | d2 | d3) >= 0) { // the common case: no padding, every character base64
            const unsigned v =
                unsigned(a) << 18 | unsigned(b) << 12 | unsigned(d2) << 6 | unsigned(d3);
            bytes[0] = static_cast<unsigned char>(v >> 16);
            bytes[1] = static_cast<unsigned char>(v >> 8);
            bytes[2] = static_cast<unsigned char>(v);
            return 3;
        }
        if (a < 0 || b < 0 || d2 == -1 || d3 == -1 || (d2 == -2 && d3 != -2)) return 0;
        bytes[0] = static_cast<unsigned char>(a << 2 | b >> 4);
        if (d2 < 0) return 1;
        bytes[1] = static_cast<unsigned char>((b & 15) << 4 | d2 >> 2);
        return 2;
    }
    FileRangeReader text_;
    std::int64_t length_;
};

// Bytes decoded into memory for as long as the reader lives (a JPEG written as base64: below).
class DecodedReader final : private std::string, public OIIO::Filesystem::IOMemReader {
  public:
    explicit DecodedReader(std::string bytes)
        : std::string(std::move(bytes)),
          IOMemReader(const_cast<char*>(std::string::data()), std::string::size()) {}
};

// A JPEG's bytes, mapped: OpenImageIO's JPEG reader takes an IOProxy only as a FILE* or as
// bytes in memory (IOMemReader), and a mapping is bytes in memory that the kernel reads from the
// file as the decoder touches them. Its pages are clean, shared with the page cache, and go with
// the mapping (a JPEG's encoded bytes are a tenth or less of its texels).
struct Mapping {
    void* base = nullptr;
    size_t size = 0;
    const char* bytes = nullptr;
    explicit Mapping(const EmbeddedImage& image) {
        const int fd = ::open(image.file.c_str(), O_RDONLY | O_CLOEXEC);
        const std::uint64_t page = std::uint64_t(::sysconf(_SC_PAGESIZE));
        const std::uint64_t start = image.offset / page * page;
        size = size_t(image.offset + image.length - start);
        base =
            fd < 0 ? MAP_FAILED : ::mmap(nullptr, size, PROT_READ, MAP_PRIVATE, fd, off_t(start));
        if (fd >= 0) ::close(fd);
        if (base == MAP_FAILED)
            throw std::runtime_error("cannot map '" + image.file + "': " + std::strerror(errno));
        bytes = static_cast<const char*>(base) + (image.offset - start);
    }
    ~Mapping() { ::munmap(base, size); }
    Mapping(const Mapping&) = delete;
    Mapping& operator=(const Mapping&) = delete;
};

class MappedReader final : private Mapping, public OIIO::Filesystem::IOMemReader {
  public:
    MappedReader(const EmbeddedImage& image)
        : Mapping(image), IOMemReader(const_cast<char*>(bytes), size_t(image.length)) {}
};

} // namespace

std::unique_ptr<OIIO::Filesystem::IOProxy> embeddedReader(const EmbeddedImage& image) {
    if (image.bytes)
        return std::make_unique<OIIO::Filesystem::IOMemReader>(
            const_cast<char*>(image.bytes->data()), image.bytes->size());
    std::unique_ptr<OIIO::Filesystem::IOProxy> reader;
    if (image.base64)
        reader = std::make_unique<Base64Reader>(image);
    else
        reader = std::make_unique<FileRangeReader>(image); // checks the file holds the image
    unsigned char magic[2] = {};
    const bool jpeg =
        image.length > 0 && reader->pread(magic, 2, 0) == 2 && magic[0] == 0xFF && magic[1] == 0xD8;
    if (!jpeg) return reader;
    if (!image.base64) return std::make_unique<MappedReader>(image);
    // OpenImageIO reads a JPEG only from memory or a FILE*: its bytes are decoded for as long
    // as the reader is open (the cache's open file), never for the whole render.
    std::string bytes(size_t(image.length), '\0');
    bytes.resize(reader->pread(bytes.data(), bytes.size(), 0));
    return std::make_unique<DecodedReader>(std::move(bytes));
}

} // namespace spw
