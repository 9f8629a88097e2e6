// The --preview window (GLFW): the image as iterations complete, in sRGB with an exposure the
// keys change (+/= brighter by a stop, - darker, 0 back to 0), the progress and the error
// estimate in its title. Closing it, Esc or q stop the render as Ctrl-C does; so does losing the
// display (the X server or an X-forwarding ssh connection gone), which Xlib would otherwise end
// the process for.
//
// GLFW wants its window on the main thread, so the render runs on a thread of its own and
// publish()es each iteration's image; the main thread pump()s events and redraws only when a new
// image or exposure arrives. The image is converted to sRGB with the PNG writer's own function,
// so a screenshot of the window at exposure 0 equals the PNG of the same iterations.
#pragma once

#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

struct GLFWwindow;

namespace spw {

class PreviewWindow {
  public:
    // Opens a width x height window. Throws std::runtime_error when there is no display.
    PreviewWindow(int width, int height, const std::string& title);
    ~PreviewWindow();
    PreviewWindow(const PreviewWindow&) = delete;
    PreviewWindow& operator=(const PreviewWindow&) = delete;

    // Any thread: the latest image (linear RGB, row-major) and the title's progress text.
    void publish(std::vector<float> rgb, const std::string& status);
    // Any thread: ends the main thread's current pump() wait early.
    void wake();
    // Main thread: handles events and redraws if something changed, waiting up to `seconds`
    // for events. Returns false once the user asked to close the window, or the display is lost.
    bool pump(double seconds);
    // Whether the display went away; the window is not touched again once it did.
    bool lost() const;

  private:
    void draw();
    GLFWwindow* window_ = nullptr;
    int width_, height_;
    std::string name_;
    int exposure_ = 0; // stops
    bool dirty_ = true;
    std::mutex mutex_; // guards what publish() hands over
    std::vector<float> pending_;
    std::string status_;
    bool fresh_ = false;
    std::vector<float> shown_;         // the image on screen, linear
    std::vector<std::uint8_t> pixels_; // as drawn, sRGB
};

} // namespace spw
