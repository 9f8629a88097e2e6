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
    FileRangeReader(const EmbeddedImage& image)
        : IOProxy(image.file, Read), offset_(std::int64_t(image.offset)),
          length_(std::int64_t(image.length)) {
        fd_ = ::open(image.file.c_str(), O_RDONLY | O_CLOEXEC);
        struct stat st {};
        if (fd_ < 0 || ::fstat(fd_, &st) != 0) {
            const std::string why = std::strerror(errno);
            if (fd_ >= 0) ::close(fd_);
            throw std::runtime_error("cannot open '" + image.file + "': " + why);
        }
        if (std::uint64_t(st.st_size) < image.offset + image.length) {
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
    auto reader = std::make_unique<FileRangeReader>(image); // checks the file holds the image
    unsigned char magic[2] = {};
    if (image.length > 0 && reader->pread(magic, 2, 0) == 2 && magic[0] == 0xFF && magic[1] == 0xD8)
        return std::make_unique<MappedReader>(image); // a JPEG
    return reader;
}

} // namespace spw
