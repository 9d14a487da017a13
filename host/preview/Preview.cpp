#include "preview/Preview.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>
#include <sstream>
#include <vector>

#define GLFW_INCLUDE_VULKAN
#include <GLFW/glfw3.h>

#include "gpu/ComputeRenderer.h"
#include "image/ImageIO.h"
#include "preview/OrbitCamera.h"
#include "preview/Presenter.h"
#include "scene/Parser.h"

namespace snell {

const char* const kPreviewKeys =
    "Preview controls:\n"
    "  left drag             orbit around the point the camera looks at\n"
    "  right or shift drag   pan\n"
    "  wheel                 zoom\n"
    "  R                     restore the scene's camera\n"
    "  [ ]                   maximum depth down / up\n"
    "  1 2 3                 shadows / reflection / refraction on or off\n"
    "  A                     supersampling on or off\n"
    "  S                     screenshot: a PNG of the rendered image next to the scene\n"
    "  H                     print these keys\n"
    "  Esc, Q                close\n"
    "Saving the scene file re-renders it; an error keeps the last image.";

namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

double msBetween(Clock::time_point a, Clock::time_point b) {
    return std::chrono::duration<double, std::milli>(b - a).count();
}

// The moving camera: frames rendered small enough to take at most this long
// (10 frames a second with room for the rest of the loop), and the camera
// counts as still this long after its last move.
constexpr double kMovingFrameMs = 60.0;
constexpr double kStillAfterMs = 150.0;

// What the window's callbacks tell the loop.
struct Input {
    OrbitCamera* camera = nullptr;
    bool cameraMoved = false;
    bool redraw = false;
    bool dragging = false, panning = false;
    double lastX = 0.0, lastY = 0.0;
    std::vector<int> keys;  // pressed since the loop last looked
};

Input& inputOf(GLFWwindow* window) { return *static_cast<Input*>(glfwGetWindowUserPointer(window)); }

double windowSize(GLFWwindow* window) {
    int w = 0, h = 0;
    glfwGetWindowSize(window, &w, &h);
    return std::max(1, std::min(w, h));
}

void onMouseButton(GLFWwindow* window, int button, int action, int mods) {
    Input& in = inputOf(window);
    const bool pressed = action == GLFW_PRESS;
    if (button == GLFW_MOUSE_BUTTON_LEFT) {
        in.dragging = pressed;
        in.panning = pressed && (mods & GLFW_MOD_SHIFT);
    } else if (button == GLFW_MOUSE_BUTTON_RIGHT) {
        in.dragging = in.panning = pressed;
    }
    glfwGetCursorPos(window, &in.lastX, &in.lastY);
}

void onCursor(GLFWwindow* window, double x, double y) {
    Input& in = inputOf(window);
    if (in.dragging) {
        const double dx = x - in.lastX, dy = y - in.lastY;
        if (in.panning) in.camera->pan(dx, dy, windowSize(window));
        else in.camera->orbit(dx, dy, windowSize(window));
        in.cameraMoved = true;
    }
    in.lastX = x;
    in.lastY = y;
}

void onScroll(GLFWwindow* window, double, double dy) {
    Input& in = inputOf(window);
    in.camera->zoom(dy);
    in.cameraMoved = true;
}

void onKey(GLFWwindow* window, int key, int, int action, int) {
    if (action == GLFW_PRESS || action == GLFW_REPEAT) inputOf(window).keys.push_back(key);
}

void onRefresh(GLFWwindow* window) { inputOf(window).redraw = true; }
void onFramebufferSize(GLFWwindow* window, int, int) { inputOf(window).redraw = true; }

// The first free NAME-shot-NNN.png beside the scene file.
std::string screenshotPath(const std::string& scenePath) {
    const fs::path p(scenePath);
    for (int n = 1;; ++n) {
        char suffix[32];
        std::snprintf(suffix, sizeof suffix, "-shot-%03d.png", n);
        fs::path candidate = p.parent_path() / (p.stem().string() + suffix);
        if (!fs::exists(candidate)) return candidate.string();
    }
}

fs::file_time_type modificationTime(const std::string& path) {
    std::error_code ignored;
    return fs::last_write_time(path, ignored);
}

class Session {
public:
    explicit Session(const PreviewOptions& o) : o_(o) {}
    void run();

private:
    void loadScene(std::unique_ptr<Scene> scene);
    void initGlfw();
    vk::ContextOptions contextOptions() const;
    void connectInput();
    void reload();
    void reloadIfChanged();
    void reportReload();
    // Renders and shows frames until the window closes (or the scripted frames are shown).
    void showFrames();
    void printFrameTimes(int framesShown, const std::vector<double>& renderMs, const std::vector<double>& frameMs) const;
    void handleKeys();
    void renderFrame();
    void updateTitle();
    void saveScreenshot(const std::string& path);
    void resetAccumulation() { samplesDone_ = 0; }
    bool moving() const;
    void chooseMovingScale();
    int supersample() const { return supersampleOn_ ? std::max(2, sceneSupersample()) : 1; }
    int sceneSupersample() const { return o_.supersample.value_or(scene_->supersample); }

    const PreviewOptions& o_;
    GLFWwindow* window_ = nullptr;
    std::unique_ptr<vk::Context> context_;
    std::unique_ptr<Presenter> presenter_;
    std::unique_ptr<Scene> scene_;
    std::unique_ptr<ComputeRenderer> renderer_;
    OrbitCamera camera_;
    Input input_;
    TraceSettings trace_ = kPreviewSettings;
    bool supersampleOn_ = true;
    int size_ = 0;
    // The image so far: the sum of samplesDone_ one-sample images.
    Image sum_, mean_;
    int samplesDone_ = 0;
    std::vector<std::uint8_t> bytes_;
    bool haveImage_ = false;
    double lastFrameMs_ = 0.0, lastRaysPerSecond_ = 0.0;
    // While the camera moves, frames are rendered 1/movingScale_ a side, one
    // sample each, sized to keep kMovingFrameMs; still, the full image refines.
    int movingScale_ = 1;
    int frameSide_ = 0;  // the side of the image in bytes_
    Clock::time_point lastMove_{};
    std::string error_;  // the last reload's error, shown in the title
    fs::file_time_type sceneTime_{};
    Clock::time_point lastPoll_{};
    // A reload in flight: when the file changed, until its first image shows.
    std::optional<Clock::time_point> reloadStart_;
    std::optional<std::chrono::system_clock::time_point> savedAt_;
};

void Session::loadScene(std::unique_ptr<Scene> scene) {
    const bool keepCamera = scene_ && !camera_.atHome();
    size_ = o_.size.value_or(scene->imageSize);
    const Camera home = Camera::fromSpec(size_, scene->halfWidth);
    RendererOptions options;
    options.precision = o_.precision;
    options.traversal = o_.traversal;
    auto renderer = std::make_unique<ComputeRenderer>(*context_, *scene, home, options);
    renderer_ = std::move(renderer);  // the old renderer goes before its scene
    scene_ = std::move(scene);
    if (!keepCamera) camera_ = OrbitCamera(*scene_, home, scene_->halfWidth);
    sum_ = Image(size_, size_);
    resetAccumulation();
}

void Session::reload() {
    reloadStart_ = Clock::now();
    try {
        auto scene = std::make_unique<Scene>(parseSceneFile(o_.scene));
        if (!o_.quiet)
            for (const Diagnostic& w : scene->warnings) std::cerr << w.format("warning") << "\n";
        loadScene(std::move(scene));
        error_.clear();
    } catch (const ParseError& e) {
        std::cerr << e.what() << "\n";
        // The title has room for one line: the first error (SPEC §7).
        const bool more = e.diagnostics().size() > 1 || e.notShown() > 0;
        error_ = e.diagnostic().format("error") + (more ? " (more on standard error)" : "");
        reloadStart_.reset();
    }
    updateTitle();
}

void Session::handleKeys() {
    std::vector<int> keys;
    keys.swap(input_.keys);
    for (int key : keys) {
        switch (key) {
        case GLFW_KEY_ESCAPE:
        case GLFW_KEY_Q: glfwSetWindowShouldClose(window_, GLFW_TRUE); break;
        case GLFW_KEY_R: camera_.reset(); resetAccumulation(); break;
        case GLFW_KEY_LEFT_BRACKET:
            trace_.maxDepth = std::max(0, trace_.maxDepth - 1);
            resetAccumulation();
            break;
        case GLFW_KEY_RIGHT_BRACKET:
            trace_.maxDepth = std::min(256, trace_.maxDepth + 1);
            resetAccumulation();
            break;
        case GLFW_KEY_1: trace_.shadows = !trace_.shadows; resetAccumulation(); break;
        case GLFW_KEY_2: trace_.reflection = !trace_.reflection; resetAccumulation(); break;
        case GLFW_KEY_3: trace_.refraction = !trace_.refraction; resetAccumulation(); break;
        case GLFW_KEY_A: supersampleOn_ = !supersampleOn_; resetAccumulation(); break;
        case GLFW_KEY_H: std::cout << kPreviewKeys << std::endl; break;
        case GLFW_KEY_S:
            if (haveImage_) saveScreenshot(screenshotPath(o_.scene));
            break;
        default: break;
        }
    }
    updateTitle();
}

void Session::saveScreenshot(const std::string& path) {
    writeImage(path, mean_, {{"Title", scene_->name}, {"Source", o_.scene}, {"Software", "snell preview"}});
    if (!o_.quiet) std::cerr << "snell: screenshot " << path << "\n";
}

// The camera moved within the last moment (or a drag holds it).
bool Session::moving() const {
    return input_.dragging || msBetween(lastMove_, Clock::now()) < kStillAfterMs;
}

// The scale that keeps a moving frame within kMovingFrameMs, from the last
// frame's time: the render time goes with the number of pixels.
void Session::chooseMovingScale() {
    if (lastFrameMs_ <= 0.0) return;
    const double fullMs = lastFrameMs_ * double(movingScale_) * double(movingScale_);
    int scale = 1;
    while (scale < size_ / 16 && fullMs / double(scale * scale) > kMovingFrameMs) ++scale;
    movingScale_ = scale;
}

void Session::renderFrame() {
    // Moving: a quick low-resolution look, one sample, nothing accumulated.
    const bool quick = moving();
    const int side = quick ? std::max(1, size_ / movingScale_) : size_;
    RenderRequest request;
    request.width = request.height = side;
    request.supersample = quick ? 1 : supersample();
    request.firstSample = quick ? 0 : samplesDone_;
    request.sampleCount = 1;  // progressive: one sub-pixel sample a frame
    request.camera = camera_.camera(side, side);
    request.trace = trace_;
    request.cancel = o_.cancel;
    const GpuRenderResult r = renderer_->render(request, true);
    if (quick) {
        mean_ = r.image;
        samplesDone_ = 0;  // the full image starts afresh once the camera stops
    } else {
        if (samplesDone_ == 0) std::fill(sum_.rgb.begin(), sum_.rgb.end(), 0.0f);
        for (std::size_t i = 0; i < sum_.rgb.size(); ++i) sum_.rgb[i] += r.image.rgb[i];
        ++samplesDone_;
        mean_ = Image(size_, size_);
        const float inverse = 1.0f / float(samplesDone_);
        for (std::size_t i = 0; i < sum_.rgb.size(); ++i)
            mean_.rgb[i] = samplesDone_ == 1 ? sum_.rgb[i] : sum_.rgb[i] * inverse;
    }
    frameSide_ = side;
    bytes_.resize(std::size_t(side) * side * 4);
    for (std::size_t p = 0; p < std::size_t(side) * side; ++p) {
        for (int k = 0; k < 3; ++k) bytes_[p * 4 + k] = toByte(mean_.rgb[p * 3 + k]);
        bytes_[p * 4 + 3] = 255;
    }
    haveImage_ = true;
    lastFrameMs_ = r.renderMs;
    lastRaysPerSecond_ = r.renderMs > 0.0 ? double(r.rays.total()) / (r.renderMs * 1e-3) : 0.0;
    if (quick) chooseMovingScale();
}

void Session::updateTitle() {
    std::ostringstream t;
    t.precision(3);
    t << "snell preview: " << (scene_ ? scene_->name : o_.scene);
    if (!error_.empty()) {
        t << " | " << error_;
    } else {
        const int s = supersample();
        t << " | " << lastFrameMs_ << " ms/frame, " << lastRaysPerSecond_ * 1e-6 << " Mrays/s";
        if (frameSide_ != size_) t << ", moving: " << frameSide_ << "x" << frameSide_;
        t << " | depth "
          << trace_.maxDepth << ", shadows " << (trace_.shadows ? "on" : "off") << ", reflection "
          << (trace_.reflection ? "on" : "off") << ", refraction " << (trace_.refraction ? "on" : "off") << ", spp "
          << s << "x" << s << " (" << samplesDone_ << "/" << s * s << ")";
    }
    glfwSetWindowTitle(window_, t.str().c_str());
}

// GLFW, with a Vulkan loader for windows; WindowError says what is missing.
void Session::initGlfw() {
    if (!glfwInit())
        throw WindowError("cannot open a window (no display? set DISPLAY, or run under Xvfb: xvfb-run snell preview ...)");
    if (!glfwVulkanSupported()) {
        glfwTerminate();
        throw WindowError("GLFW finds no Vulkan loader for windows; install libvulkan1 and mesa-vulkan-drivers");
    }
}

// The Vulkan context a window needs: GLFW's instance extensions, a swapchain.
vk::ContextOptions Session::contextOptions() const {
    std::uint32_t count = 0;
    const char** required = glfwGetRequiredInstanceExtensions(&count);
    vk::ContextOptions options;
    options.deviceIndex = o_.gpu;
    options.validation = o_.validation;
    options.pipelineCachePath = o_.pipelineCachePath;
    options.rayQueries = o_.rayQueries;
    for (std::uint32_t i = 0; i < count; ++i) options.instanceExtensions.push_back(required[i]);
    options.deviceExtensions.push_back(VK_KHR_SWAPCHAIN_EXTENSION_NAME);
    return options;
}

// Mouse and keys move the camera (input_), and the window asks for redraws.
void Session::connectInput() {
    input_.camera = &camera_;
    glfwSetWindowUserPointer(window_, &input_);
    glfwSetMouseButtonCallback(window_, onMouseButton);
    glfwSetCursorPosCallback(window_, onCursor);
    glfwSetScrollCallback(window_, onScroll);
    glfwSetKeyCallback(window_, onKey);
    glfwSetWindowRefreshCallback(window_, onRefresh);
    glfwSetFramebufferSizeCallback(window_, onFramebufferSize);
}

// Hot reload: the file's modification time, looked at 4 times a second.
void Session::reloadIfChanged() {
    if (msBetween(lastPoll_, Clock::now()) < 250.0) return;
    lastPoll_ = Clock::now();
    const fs::file_time_type t = modificationTime(o_.scene);
    if (t == sceneTime_) return;
    sceneTime_ = t;
    savedAt_ = std::chrono::file_clock::to_sys(t);
    reload();
}

// The first frame after a reload is shown: how long it took.
void Session::reportReload() {
    const double ms = msBetween(*reloadStart_, Clock::now());
    if (!o_.quiet) {
        std::cerr << "snell: reloaded " << o_.scene << ": new image " << ms << " ms after the change was seen";
        if (savedAt_)
            std::cerr << ", "
                      << std::chrono::duration<double, std::milli>(std::chrono::system_clock::now() - *savedAt_).count()
                      << " ms after the save";
        std::cerr << "\n";
    }
    reloadStart_.reset();
}

// A scripted run's frame times (rendered frames only), medians.
void Session::printFrameTimes(int framesShown, const std::vector<double>& renderMs,
                              const std::vector<double>& frameMs) const {
    auto median = [](std::vector<double> v) {
        std::sort(v.begin(), v.end());
        return v[v.size() / 2];
    };
    std::cerr << "snell: " << framesShown << " frames shown, " << frameMs.size() << " rendered ("
              << (o_.orbitPerFrame != 0.0
                      ? "moving, " + std::to_string(frameSide_) + "x" + std::to_string(frameSide_) + " of "
                      : std::string())
              << size_ << "x" << size_ << "): median " << median(renderMs) << " ms rendering, " << median(frameMs)
              << " ms a frame in all (" << 1000.0 / median(frameMs) << " frames a second)\n";
}

void Session::showFrames() {
    int framesShown = 0;
    std::vector<double> renderMs, frameMs;  // per shown frame: the dispatches, and the whole loop
    Clock::time_point lastShown = Clock::now();
    while (!glfwWindowShouldClose(window_)) {
        if (o_.cancel && o_.cancel->load()) break;
        const bool refining = samplesDone_ < supersample() * supersample() || frameSide_ != size_;
        if (refining || o_.frames > 0) glfwPollEvents();
        else glfwWaitEventsTimeout(0.25);  // idle: sleep, waking only to look at the scene file
        if (o_.frames > 0 && o_.orbitPerFrame != 0.0) {  // scripted drag
            camera_.orbitDegrees(o_.orbitPerFrame);
            input_.cameraMoved = true;
        }
        if (input_.cameraMoved) {
            input_.cameraMoved = false;
            lastMove_ = Clock::now();
            resetAccumulation();
        }
        handleKeys();

        reloadIfChanged();

        int fbWidth = 0, fbHeight = 0;
        glfwGetFramebufferSize(window_, &fbWidth, &fbHeight);
        if (fbWidth == 0 || fbHeight == 0) continue;  // minimised: wait for events, render nothing

        // Scripted, every pass shows a frame (the finished image again once refined).
        bool show = (input_.redraw || o_.frames > 0) && haveImage_;
        bool rendered = false;
        if (samplesDone_ < supersample() * supersample() || moving() || frameSide_ != size_) {
            renderFrame();
            show = rendered = true;
        }
        if (!show) continue;
        input_.redraw = false;
        if (!presenter_->present(bytes_, frameSide_, frameSide_)) {
            input_.redraw = true;  // the swapchain was rebuilt: show it again next time round
            continue;
        }
        ++framesShown;
        if (rendered) {
            renderMs.push_back(lastFrameMs_);
            frameMs.push_back(msBetween(lastShown, Clock::now()));
        }
        lastShown = Clock::now();
        updateTitle();
        if (reloadStart_) reportReload();
        if (o_.frames > 0 && framesShown >= o_.frames) {
            if (!o_.screenshot.empty()) saveScreenshot(o_.screenshot);
            break;
        }
    }
    if (o_.frames > 0 && !o_.quiet && !frameMs.empty()) printFrameTimes(framesShown, renderMs, frameMs);
}

void Session::run() {
    auto first = std::make_unique<Scene>(parseSceneFile(o_.scene));  // ParseError: the caller's
    if (!o_.quiet)
        for (const Diagnostic& w : first->warnings) std::cerr << w.format("warning") << "\n";
    sceneTime_ = modificationTime(o_.scene);
    supersampleOn_ = o_.supersample.value_or(first->supersample) > 1;
    if (o_.depth) trace_.maxDepth = *o_.depth;
    if (o_.minWeight) trace_.minWeight = *o_.minWeight;

    initGlfw();
    struct Terminate {
        GLFWwindow*& window;
        ~Terminate() {
            if (window) glfwDestroyWindow(window);
            glfwTerminate();
        }
    } terminate{window_};

    const int side = o_.size.value_or(first->imageSize);
    const int windowSide = std::min(side, 1024);  // larger images are shown scaled down
    glfwWindowHint(GLFW_CLIENT_API, GLFW_NO_API);
    window_ = glfwCreateWindow(windowSide, windowSide, "snell preview", nullptr, nullptr);
    if (!window_) throw WindowError("GLFW could not create a window");

    context_ = std::make_unique<vk::Context>(contextOptions());
    struct Release {  // Vulkan objects go before the window and GLFW
        Session& s;
        ~Release() {
            s.presenter_.reset();
            s.renderer_.reset();
            s.context_.reset();
        }
    } release{*this};
    presenter_ = std::make_unique<Presenter>(*context_, window_);
    loadScene(std::move(first));
    if (o_.orbitDegrees != 0.0) camera_.orbitDegrees(o_.orbitDegrees);

    connectInput();
    updateTitle();

    showFrames();
    if (o_.validation && context_->validationMessages() > 0)
        throw vk::VulkanError("the Vulkan validation layer reported " +
                              std::to_string(context_->validationMessages()) + " message(s)");
}

}  // namespace

void runPreview(const PreviewOptions& options) {
    Session session(options);
    session.run();
}

}  // namespace snell
