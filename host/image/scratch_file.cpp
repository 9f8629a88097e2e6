#include "host/image/scratch_file.h"

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <fcntl.h>
#include <sstream>
#include <stdexcept>
#include <sys/statvfs.h>
#include <unistd.h>
#include <vector>

namespace spw {

std::string scratchFolder(const std::string& configured) {
    std::string dir = configured;
    for (const char* var : {"TMPDIR", "TMP", "TEMP", "TEMPDIR"})
        if (dir.empty() && std::getenv(var) && *std::getenv(var)) dir = std::getenv(var);
    return dir.empty() ? "/tmp" : dir;
}

int openScratchFile(const std::string& dir, const char* what) {
    int fd = -1;
#ifdef O_TMPFILE
    fd = ::open(dir.c_str(), O_TMPFILE | O_RDWR | O_CLOEXEC, 0600);
#endif
    if (fd < 0) {
        // No O_TMPFILE here: make a named file and unlink it before anything else happens.
        std::string templ = dir + "/spillway-" + what + "-XXXXXX";
        std::vector<char> name(templ.begin(), templ.end());
        name.push_back('\0');
        fd = ::mkostemp(name.data(), O_CLOEXEC);
        if (fd >= 0) ::unlink(name.data());
    }
    if (fd < 0)
        throw std::runtime_error(std::string("cannot create a ") + what + " file in '" + dir +
                                 "': " + std::strerror(errno));
    return fd;
}

std::string fullFolder(const std::string& dir, std::uint64_t bytes, const char* what) {
    struct statvfs st {};
    if (::statvfs(dir.c_str(), &st) != 0) return "";
    const std::uint64_t free = std::uint64_t(st.f_bavail) * st.f_frsize;
    if (free >= bytes) return "";
    std::ostringstream out;
    out.precision(1);
    out << std::fixed << "the scratch folder '" << dir << "' is full (" << double(free) / 1048576.0
        << " MiB free, the " << what << " needs " << double(bytes) / 1048576.0
        << " MiB; --spill-dir chooses another)";
    return out.str();
}

} // namespace spw
