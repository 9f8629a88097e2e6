// The --preview window, for real, under Xvfb: a screenshot of it (xwd) after a few iterations
// equals the PNG of that many iterations within quantisation; closing it stops the render as
// Ctrl-C does (image written, exit 0, stop_reason "window"); without a display, exit 2 before
// rendering.
#include "test_util.h"

#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <chrono>
#include <csignal>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sys/wait.h>
#include <thread>
#include <unistd.h>

// Xlib last: its macros (None, Bool, Status) collide with GoogleTest's names.
#include <X11/Xlib.h>

namespace spw::test {
namespace {

// An Xvfb server on a display of its own for the test's lifetime; DISPLAY set to it.
class VirtualDisplay {
  public:
    VirtualDisplay() {
        // A display number of its own: from the pid, past any that has a lock file.
        number_ = 100 + int(getpid() % 800);
        while (std::filesystem::exists("/tmp/.X" + std::to_string(number_) + "-lock"))
            ++number_;
        const std::string logPath = log(); // this process's: the child's pid differs
        pid_ = fork();
        if (pid_ == 0) {
            std::freopen(logPath.c_str(), "w", stderr);
            const std::string display = ":" + std::to_string(number_);
            execlp("Xvfb", "Xvfb", display.c_str(), "-screen", "0", "640x480x24", "-nolisten",
                   "tcp", "-noreset", static_cast<char*>(nullptr));
            _exit(127);
        }
        setenv("DISPLAY", name().c_str(), 1);
        // Ready means a client can connect: try until one does.
        for (int i = 0; i < 200 && !ready_; ++i) {
            if (Display* d = XOpenDisplay(nullptr)) {
                XCloseDisplay(d);
                ready_ = true;
            } else {
                std::this_thread::sleep_for(std::chrono::milliseconds(25));
            }
        }
    }
    ~VirtualDisplay() {
        unsetenv("DISPLAY");
        stop(SIGTERM);
        std::filesystem::remove(log());
    }
    // Ends the server (SIGKILL: gone at once, as a dropped ssh connection's forwarded display).
    void stop(int signal = SIGKILL) {
        if (pid_ <= 0) return;
        kill(pid_, signal);
        waitpid(pid_, nullptr, 0);
        pid_ = -1;
    }
    bool ready() const { return ready_; }
    std::string describe() const {
        int status = 0;
        const bool alive = waitpid(pid_, &status, WNOHANG) == 0;
        return "display " + name() + ", socket " +
               (std::filesystem::exists("/tmp/.X11-unix/X" + std::to_string(number_)) ? "present"
                                                                                      : "absent") +
               ", Xvfb " + (alive ? "running" : "exited " + std::to_string(status));
    }
    // Xvfb's own messages, for a failure's report.
    static std::string log() {
        return (std::filesystem::temp_directory_path() /
                ("spillway-xvfb-" + std::to_string(getpid()) + ".log"))
            .string();
    }
    std::string name() const { return ":" + std::to_string(number_); }

  private:
    int number_ = 0;
    pid_t pid_ = -1;
    bool ready_ = false;
};

// The preview window's id and the spp its title shows, from the X server's window tree.
struct WindowInfo {
    std::string id;
    int spp = -1;
};
WindowInfo findPreview() {
    const CommandResult tree = runShell("xwininfo -root -tree");
    static const std::regex line(R"((0x[0-9a-f]+) "Spillway: box\.yaml - (\d+)/\d+ spp)");
    std::smatch m;
    if (std::regex_search(tree.output, m, line)) return {m[1].str(), std::stoi(m[2].str())};
    return {};
}

// The pixels of an xwd dump (ZPixmap, 32 bits a pixel, masks 0xff0000/0xff00/0xff) as RGB.
std::vector<std::uint8_t> readXwd(const std::string& path, int& width, int& height) {
    const std::string bytes = readFile(path);
    auto word = [&](size_t i) {
        const auto* p = reinterpret_cast<const unsigned char*>(bytes.data()) + 4 * i;
        return std::uint32_t(p[0]) << 24 | std::uint32_t(p[1]) << 16 | std::uint32_t(p[2]) << 8 |
               p[3];
    };
    if (bytes.size() < 100) return {};
    const std::uint32_t headerSize = word(0), byteOrder = word(7), bitsPerPixel = word(11),
                        bytesPerLine = word(12), colours = word(19);
    width = int(word(4));
    height = int(word(5));
    EXPECT_EQ(bitsPerPixel, 32u);
    EXPECT_EQ(word(13 + 1), 0xff0000u); // red mask
    const size_t start = headerSize + size_t(colours) * 12;
    std::vector<std::uint8_t> rgb(size_t(width) * size_t(height) * 3);
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x) {
            const auto* p = reinterpret_cast<const unsigned char*>(bytes.data()) + start +
                            size_t(y) * bytesPerLine + size_t(x) * 4;
            const std::uint32_t v = byteOrder == 0
                                        ? (std::uint32_t(p[3]) << 24 | std::uint32_t(p[2]) << 16 |
                                           std::uint32_t(p[1]) << 8 | p[0])
                                        : (std::uint32_t(p[0]) << 24 | std::uint32_t(p[1]) << 16 |
                                           std::uint32_t(p[2]) << 8 | p[3]);
            std::uint8_t* o = &rgb[(size_t(y) * size_t(width) + size_t(x)) * 3];
            o[0] = std::uint8_t(v >> 16);
            o[1] = std::uint8_t(v >> 8);
            o[2] = std::uint8_t(v);
        }
    return rgb;
}

std::vector<std::uint8_t> readPng8(const std::string& path) {
    auto in = OIIO::ImageInput::open(path);
    if (!in) return {};
    std::vector<std::uint8_t> rgb(size_t(in->spec().width) * size_t(in->spec().height) * 3);
    in->read_image(0, 0, 0, 3, OIIO::TypeDesc::UINT8, rgb.data());
    return rgb;
}

// Asks the window manager's way to close a window: WM_DELETE_WINDOW, as a close button does.
void closeWindow(const std::string& id) {
    Display* d = XOpenDisplay(nullptr);
    ASSERT_NE(d, nullptr);
    XEvent e = {};
    e.xclient.type = ClientMessage;
    e.xclient.window = Window(std::stoul(id, nullptr, 16));
    e.xclient.message_type = XInternAtom(d, "WM_PROTOCOLS", False);
    e.xclient.format = 32;
    e.xclient.data.l[0] = long(XInternAtom(d, "WM_DELETE_WINDOW", False));
    e.xclient.data.l[1] = CurrentTime;
    XSendEvent(d, e.xclient.window, False, NoEventMask, &e);
    XFlush(d);
    XCloseDisplay(d);
}

TEST(Preview, ScreenshotMatchesTheImageAndClosingStopsTheRender) {
    VirtualDisplay display;
    ASSERT_TRUE(display.ready()) << "Xvfb did not start (scripts/install-deps.sh installs xvfb)\n"
                                 << readFile(VirtualDisplay::log()) << display.describe();
    TempDir dir;
    const std::string scene = smallCornellBox(dir, 64, 48);
    WindowInfo shown;
    int shotWidth = 0, shotHeight = 0;
    std::vector<std::uint8_t> shot;
    ChildResult r =
        runChild({"render", scene, "--backend", "cpu", "--preview", "--progress", "lines", "--spp",
                  "100000", "-o", dir.file("live.png"), "--stats", dir.file("live.json")},
                 [&](pid_t pid) {
                     if (!waitForChildOutput(pid, "iteration 3/")) return;
                     // Frozen, so that the window's title and pixels are of one iteration.
                     for (int i = 0; i < 100 && shown.spp < 3; ++i) {
                         std::this_thread::sleep_for(std::chrono::milliseconds(50));
                         kill(pid, SIGSTOP);
                         shown = findPreview();
                         if (shown.spp < 3) kill(pid, SIGCONT);
                     }
                     if (shown.spp >= 3) {
                         const CommandResult dump = runShell("xwd -silent -id " + shown.id +
                                                             " -out " + dir.file("shot.xwd"));
                         EXPECT_EQ(dump.status, 0) << dump.output;
                         shot = readXwd(dir.file("shot.xwd"), shotWidth, shotHeight);
                         kill(pid, SIGCONT);
                         closeWindow(shown.id);
                     } else {
                         kill(pid, SIGCONT);
                         kill(pid, SIGKILL);
                     }
                 });
    ASSERT_GE(shown.spp, 3) << "no preview window with a title showing 3 spp\n" << r.output;
    // Closing the window: the image of every completed iteration, exit 0, "window".
    EXPECT_EQ(r.status, 0) << r.output;
    const nlohmann::json s = nlohmann::json::parse(std::ifstream(dir.file("live.json")));
    EXPECT_EQ(s["stop_reason"], "window");
    EXPECT_GE(s["spp"].get<int>(), shown.spp);
    EXPECT_TRUE(std::filesystem::exists(dir.file("live.png")));

    // The screenshot against the PNG of the iterations the title showed. The window sets its
    // title just after drawing, so a process frozen between the two shows the next iteration
    // under the previous title: the screenshot must equal the PNG of spp or spp + 1 (a wrong
    // conversion, orientation or exposure matches neither).
    ASSERT_EQ(shotWidth, 64);
    ASSERT_EQ(shotHeight, 48);
    int best = 256;
    for (int spp : {shown.spp, shown.spp + 1}) {
        const std::string png = dir.file("ref" + std::to_string(spp) + ".png");
        ChildResult ref = runChild({"render", scene, "--backend", "cpu", "--quiet", "--spp",
                                    std::to_string(spp), "-o", png});
        ASSERT_EQ(ref.status, 0) << ref.output;
        const std::vector<std::uint8_t> pixels = readPng8(png);
        ASSERT_EQ(pixels.size(), shot.size());
        int worst = 0;
        double sum = 0;
        for (size_t i = 0; i < pixels.size(); ++i) {
            worst = std::max(worst, std::abs(int(pixels[i]) - int(shot[i])));
            sum += pixels[i];
        }
        EXPECT_GT(sum / double(pixels.size()), 10.0) << "a black image proves nothing";
        best = std::min(best, worst);
    }
    EXPECT_LE(best, 1) << "the window shows neither the PNG of " << shown.spp << " spp nor of "
                       << shown.spp + 1;
}

// The display going away under the window (the X server killed; an ssh connection with X
// forwarding dropped) stops the render as SIGHUP does: every completed iteration written, the
// checkpoint too, exit 129, stop_reason "display lost". (Before: Xlib's default handler exited 1
// with nothing written.)
TEST(Preview, ALostDisplayKeepsTheFinishedWork) {
    VirtualDisplay display;
    ASSERT_TRUE(display.ready()) << readFile(VirtualDisplay::log()) << display.describe();
    TempDir dir;
    const std::string scene = smallCornellBox(dir, 32, 24);
    ChildResult r = runChild({"render", scene, "--backend", "cpu", "--preview", "--progress",
                              "lines", "--spp", "100000", "-o", dir.file("live.exr"), "--stats",
                              dir.file("live.json"), "--checkpoint", dir.file("ck.exr")},
                             [&](pid_t pid) {
                                 if (waitForChildOutput(pid, "iteration 3/"))
                                     display.stop();
                                 else
                                     kill(pid, SIGKILL);
                             });
    EXPECT_EQ(r.status, 129) << r.output;
    EXPECT_NE(r.output.find("the preview's display went away after"), std::string::npos)
        << r.output;
    ASSERT_TRUE(std::filesystem::exists(dir.file("live.json"))) << r.output;
    const nlohmann::json s = nlohmann::json::parse(std::ifstream(dir.file("live.json")));
    EXPECT_EQ(s["stop_reason"], "display lost");
    EXPECT_GE(s["spp"].get<int>(), 3);
    EXPECT_TRUE(std::filesystem::exists(dir.file("live.exr")));
    EXPECT_TRUE(std::filesystem::exists(dir.file("ck.exr")));
}

TEST(Preview, WithoutADisplayExitsTwoBeforeRendering) {
    TempDir dir;
    const std::string scene = smallCornellBox(dir, 64, 48);
    const char* saved = std::getenv("DISPLAY");
    const std::string keep = saved ? saved : "";
    unsetenv("DISPLAY");
    unsetenv("WAYLAND_DISPLAY");
    ChildResult r = runChild({"render", scene, "--backend", "cpu", "--preview", "--stats",
                              dir.file("s.json"), "-o", dir.file("x.exr")});
    if (saved) setenv("DISPLAY", keep.c_str(), 1);
    EXPECT_EQ(r.status, 2) << r.output;
    EXPECT_NE(r.output.find("--preview: no display"), std::string::npos) << r.output;
    EXPECT_FALSE(std::filesystem::exists(dir.file("x.exr")));
    EXPECT_FALSE(std::filesystem::exists(dir.file("s.json")));
}

} // namespace
} // namespace spw::test
