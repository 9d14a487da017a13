#include "reference/CpuRetrace.h"

#include <algorithm>
#include <atomic>
#include <memory>
#include <mutex>
#include <thread>

#include "reference/CpuRenderer.h"

namespace snell {

namespace {

struct Retrace {
    Retrace(const Scene& s) : scene(s) {}
    const Scene& scene;
    RenderRequest request;  // the render's settings, none of its outputs
    std::once_flag built;
    std::unique_ptr<CpuRenderer> reference;

    void operator()(std::vector<RetracedPixel>& pixels) {
        std::call_once(built, [&] { reference = std::make_unique<CpuRenderer>(scene); });
        std::atomic<std::size_t> next{0};
        auto work = [&] {
            RayCounts counts;
            for (std::size_t i; (i = next.fetch_add(1)) < pixels.size();) {
                RetracedPixel& p = pixels[i];
                const CpuRenderer::Pixel traced = reference->renderPixel(request, p.x, p.y, counts, p.samples);
                p.colour = traced.colour;
                p.truncation = traced.truncation(p.x, p.y);
                p.widening = traced.widening;
                p.gap = traced.gap;
            }
        };
        const std::size_t threads =
            std::min<std::size_t>(pixels.size(), std::max(1u, std::thread::hardware_concurrency()));
        std::vector<std::thread> pool;
        for (std::size_t t = 1; t < threads; ++t) pool.emplace_back(work);
        work();
        for (std::thread& t : pool) t.join();
    }
};

}  // namespace

std::function<void(std::vector<RetracedPixel>&)> cpuRetrace(const Scene& scene, const RenderRequest& request) {
    auto retrace = std::make_shared<Retrace>(scene);
    RenderRequest& settings = retrace->request;
    settings.camera = request.camera;
    settings.width = request.width;
    settings.height = request.height;
    settings.supersample = request.supersample;
    settings.firstSample = request.firstSample;
    settings.sampleCount = request.sampleCount;
    settings.trace = request.trace;
    return [retrace](std::vector<RetracedPixel>& pixels) { (*retrace)(pixels); };
}

}  // namespace snell
