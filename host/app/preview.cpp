#include "host/app/preview.h"

#include "host/image/image_io.h"

#include <GL/glx.h>
#include <GLFW/glfw3.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <thread>

namespace spw {
namespace {

// The X server gone (an ssh connection with X forwarding dropped, the server killed): Xlib's
// default is to print a line and exit(1), losing every finished iteration. These handlers only
// note it (libX11 >= 1.7 lets the exit handler return), and the window is not touched again.
std::atomic<bool> gDisplayLost{false};

extern "C" int onIoError(Display*) {
    gDisplayLost = true;
    return 0;
}

extern "C" void onIoErrorExit(Display*, void*) {
    gDisplayLost = true;
}

std::string lastGlfwError() {
    const char* what = nullptr;
    glfwGetError(&what);
    return what ? what : "unknown";
}

void onKey(GLFWwindow* window, int key, int /*scancode*/, int action, int /*mods*/) {
    if (action != GLFW_PRESS && action != GLFW_REPEAT) return;
    auto* self = static_cast<int*>(glfwGetWindowUserPointer(window)); // &exposure_
    switch (key) {
    case GLFW_KEY_ESCAPE:
    case GLFW_KEY_Q:
        glfwSetWindowShouldClose(window, GLFW_TRUE);
        break;
    case GLFW_KEY_EQUAL:
    case GLFW_KEY_KP_ADD:
        ++*self;
        break;
    case GLFW_KEY_MINUS:
    case GLFW_KEY_KP_SUBTRACT:
        --*self;
        break;
    case GLFW_KEY_0:
    case GLFW_KEY_KP_0:
        *self = 0;
        break;
    default:
        break;
    }
}

} // namespace

PreviewWindow::PreviewWindow(int width, int height, const std::string& title)
    : width_(width), height_(height), name_(title) {
    gDisplayLost = false;
    XSetIOErrorHandler(onIoError);
    if (!glfwInit()) throw std::runtime_error("--preview: no display (" + lastGlfwError() + ")");
    glfwWindowHint(GLFW_RESIZABLE, GLFW_FALSE);
    window_ = glfwCreateWindow(width, height, title.c_str(), nullptr, nullptr);
    if (!window_) {
        const std::string why = lastGlfwError();
        glfwTerminate();
        throw std::runtime_error("--preview: cannot open a window (" + why + ")");
    }
    glfwSetWindowUserPointer(window_, &exposure_);
    glfwSetKeyCallback(window_, onKey);
    glfwMakeContextCurrent(window_);
    // GLFW's connection, the one its window and this context use.
    if (Display* display = glXGetCurrentDisplay())
        XSetIOErrorExitHandler(display, onIoErrorExit, nullptr);
    glfwSwapInterval(0);
    shown_.assign(size_t(width) * size_t(height) * 3, 0.0f);
    draw();
}

PreviewWindow::~PreviewWindow() {
    if (gDisplayLost) return; // every call would go to a connection that is gone
    if (window_) glfwDestroyWindow(window_);
    glfwTerminate();
}

bool PreviewWindow::lost() const {
    return gDisplayLost;
}

void PreviewWindow::publish(std::vector<float> rgb, const std::string& status) {
    std::lock_guard<std::mutex> lock(mutex_);
    pending_ = std::move(rgb);
    status_ = status;
    fresh_ = true;
    wake();
}

void PreviewWindow::wake() {
    if (!gDisplayLost) glfwPostEmptyEvent(); // wakes pump()
}

bool PreviewWindow::pump(double seconds) {
    if (gDisplayLost) {
        std::this_thread::sleep_for(std::chrono::duration<double>(seconds));
        return false;
    }
    const int exposure = exposure_;
    glfwWaitEventsTimeout(seconds);
    if (gDisplayLost) return false;
    {
        std::lock_guard<std::mutex> lock(mutex_);
        if (fresh_) {
            shown_.swap(pending_);
            fresh_ = false;
            dirty_ = true;
        }
    }
    if (exposure != exposure_) dirty_ = true;
    if (dirty_) {
        draw();
        // The title after the pixels: X handles requests in order, so a title that shows an
        // iteration means its image is already in the window.
        char stops[32];
        std::snprintf(stops, sizeof stops, ", exposure %+d", exposure_);
        glfwSetWindowTitle(window_, (name_ + " - " + status_ + stops).c_str());
    }
    return !glfwWindowShouldClose(window_);
}

void PreviewWindow::draw() {
    const float scale = std::ldexp(1.0f, exposure_);
    pixels_.resize(shown_.size());
    for (size_t i = 0; i < shown_.size(); ++i)
        pixels_[i] = linearToSrgb8(exposure_ == 0 ? shown_[i] : shown_[i] * scale);
    int fbWidth = 0, fbHeight = 0;
    glfwGetFramebufferSize(window_, &fbWidth, &fbHeight);
    glViewport(0, 0, fbWidth, fbHeight);
    glClearColor(0.0f, 0.0f, 0.0f, 1.0f);
    glClear(GL_COLOR_BUFFER_BIT);
    // Row 0 of the image is its top: start at the top-left corner and draw downwards.
    glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
    glRasterPos2f(-1.0f, 1.0f);
    glPixelZoom(float(fbWidth) / float(width_), -float(fbHeight) / float(height_));
    glDrawPixels(width_, height_, GL_RGB, GL_UNSIGNED_BYTE, pixels_.data());
    glfwSwapBuffers(window_);
    glFinish();
    dirty_ = false;
}

} // namespace spw
