#include "host/image/output_file.h"

#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <fcntl.h>
#include <filesystem>
#include <stdexcept>
#include <sys/stat.h>
#include <unistd.h>

namespace spw {
namespace {

namespace fs = std::filesystem;

std::string folderOf(const std::string& path) {
    fs::path parent = fs::path(path).parent_path();
    return parent.empty() ? std::string(".") : parent.string();
}

// A name beside the destination that no other writer picks: hidden, with the pid and a counter.
std::string temporaryName(const std::string& path) {
    static int counter = 0;
    fs::path p(path);
    return (p.parent_path() / ("." + p.filename().string() + ".spillway-" +
                               std::to_string(::getpid()) + "-" + std::to_string(counter++)))
        .string();
}

// SIGINT and SIGTERM wait while the file gets its names, so that an interrupt cannot leave the
// temporary name behind between linkat and rename.
class SignalsHeld {
  public:
    SignalsHeld() {
        sigset_t set;
        sigemptyset(&set);
        sigaddset(&set, SIGINT);
        sigaddset(&set, SIGTERM);
        sigaddset(&set, SIGHUP);
        ::pthread_sigmask(SIG_BLOCK, &set, &old_);
    }
    ~SignalsHeld() { ::pthread_sigmask(SIG_SETMASK, &old_, nullptr); }

  private:
    sigset_t old_;
};

} // namespace

OutputFile::OutputFile(std::string path) : path_(std::move(path)) {
    struct stat st {};
    if (::stat(path_.c_str(), &st) == 0 && !S_ISREG(st.st_mode)) {
        if (S_ISDIR(st.st_mode)) fail("it is a folder", 0);
        inPlace_ = true;
        fd_ = ::open(path_.c_str(), O_WRONLY | O_CLOEXEC);
        if (fd_ < 0) fail("", errno);
        return;
    }
    const std::string dir = folderOf(path_);
#ifdef O_TMPFILE
    fd_ = ::open(dir.c_str(), O_TMPFILE | O_WRONLY | O_CLOEXEC, 0644);
#endif
    if (fd_ < 0) {
        tempName_ = temporaryName(path_);
        fd_ = ::open(tempName_.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
        if (fd_ < 0) {
            const int err = errno;
            tempName_.clear();
            fail("", err);
        }
    }
}

OutputFile::~OutputFile() {
    if (fd_ >= 0) ::close(fd_);
    if (!committed_ && !tempName_.empty()) ::unlink(tempName_.c_str());
}

void OutputFile::fail(const std::string& what, int err) const {
    std::string why = what;
    if (err != 0) why += (why.empty() ? "" : ": ") + std::string(std::strerror(err));
    throw std::runtime_error("cannot write '" + path_ + "': " + why);
}

void OutputFile::write(const void* data, std::size_t size) {
    const char* p = static_cast<const char*>(data);
    while (size > 0) {
        const ssize_t n = ::write(fd_, p, size);
        if (n < 0 && errno == EINTR) continue;
        if (n < 0) fail("", errno);
        if (n == 0) fail("no space left", 0);
        p += n;
        size -= std::size_t(n);
    }
}

void OutputFile::writeAt(std::uint64_t offset, const void* data, std::size_t size) {
    const char* p = static_cast<const char*>(data);
    while (size > 0) {
        const ssize_t n = ::pwrite(fd_, p, size, off_t(offset));
        if (n < 0 && errno == EINTR) continue;
        if (n < 0) fail("", errno);
        if (n == 0) fail("no space left", 0);
        p += n;
        offset += std::uint64_t(n);
        size -= std::size_t(n);
    }
}

void OutputFile::flush() {
    if (inPlace_ || flushed_) return;
    if (::fdatasync(fd_) != 0) fail("", errno);
    flushed_ = true;
}

void OutputFile::commit() {
    if (committed_) return;
    if (inPlace_) {
        const int fd = fd_;
        fd_ = -1;
        if (::close(fd) != 0) fail("", errno);
        committed_ = true;
        return;
    }
    flush();
    SignalsHeld held;
    if (tempName_.empty()) {
        std::string name = temporaryName(path_);
        const std::string self = "/proc/self/fd/" + std::to_string(fd_);
        if (::linkat(AT_FDCWD, self.c_str(), AT_FDCWD, name.c_str(), AT_SYMLINK_FOLLOW) != 0 &&
            ::linkat(fd_, "", AT_FDCWD, name.c_str(), AT_EMPTY_PATH) != 0)
            fail("cannot name the finished file", errno);
        tempName_ = name;
    }
    if (::rename(tempName_.c_str(), path_.c_str()) != 0) {
        const int err = errno;
        ::unlink(tempName_.c_str());
        tempName_.clear();
        fail("", err);
    }
    tempName_.clear();
    committed_ = true;
    const int fd = fd_;
    fd_ = -1;
    ::close(fd);
}

void writeFileAtomically(const std::string& path, const void* data, std::size_t size) {
    OutputFile file(path);
    file.write(data, size);
    file.commit();
}

void checkWritable(const std::string& path) {
    auto fail = [&](const std::string& why) {
        throw std::runtime_error("cannot write '" + path + "': " + why);
    };
    struct stat st {};
    if (::stat(path.c_str(), &st) == 0) {
        if (S_ISDIR(st.st_mode)) fail("it is a folder");
        if (!S_ISREG(st.st_mode)) {
            if (::access(path.c_str(), W_OK) != 0) fail(std::strerror(errno));
            return; // a device or FIFO is written in place
        }
    }
    const std::string dir = folderOf(path);
    if (::stat(dir.c_str(), &st) != 0) fail("folder '" + dir + "': " + std::strerror(errno));
    if (!S_ISDIR(st.st_mode)) fail("'" + dir + "' is not a folder");
    if (::access(dir.c_str(), W_OK | X_OK) != 0)
        fail("folder '" + dir + "': " + std::strerror(errno));
}

bool sameFile(const std::string& a, const std::string& b) {
    namespace fs = std::filesystem;
    std::error_code ea, eb;
    const bool hasA = fs::exists(a, ea), hasB = fs::exists(b, eb);
    if (hasA && hasB) return fs::equivalent(a, b, ea) && !ea;
    const fs::path ca = fs::weakly_canonical(fs::absolute(a, ea), ea);
    const fs::path cb = fs::weakly_canonical(fs::absolute(b, eb), eb);
    return !ea && !eb && ca == cb;
}

} // namespace spw
