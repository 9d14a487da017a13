// The CPU reference's image: its pixels (CpuRenderer::renderPixel) in bands of
// rows, on all cores, with what each pixel's truncation and decisions cost.
#include <algorithm>
#include <atomic>
#include <thread>
#include <vector>

#include "reference/CpuRenderer.h"

namespace snell {

using glm::dvec3;

PixelTruncation CpuRenderer::Pixel::truncation(int x, int y) const {
    PixelTruncation t;
    t.x = x;
    t.y = y;
    t.bound = bound;
    t.unbounded = unbounded;
    t.overBudget = overBudget;
    t.overTolerance = overTolerance;
    t.estimated = estimated;
    t.estimatedError = estimatedError;
    t.undecided = undecided;
    return t;
}

Image CpuRenderer::render(const RenderRequest& request, RayCounts* counts) const {
    // The window rendered (the whole image unless asked), in bands of rows:
    // all of them at once for an image in memory, 32 at a time when the rows
    // stream to a sink. Pixel coordinates stay those of the whole image.
    const PixelWindow area = request.area();
    const int width = area.width(), height = area.height();
    const int bandRows = request.rowSink ? std::min(32, height) : height;
    Image band(width, bandRows);
    Image image = request.rowSink ? Image() : Image(width, height);
    const int threads = request.threads > 0
                            ? request.threads
                            : static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
    std::vector<RayCounts> perThread(threads);
    std::vector<TruncationReport> truncation(threads);
    request.startTruncationImages(static_cast<std::size_t>(width) * height);
    std::atomic<int> rowsDone{0};
    std::atomic<std::uint64_t> raysTraced{0};
    for (int bandStart = 0; bandStart < height; bandStart += bandRows) {
        const int rows = std::min(bandRows, height - bandStart);
        Image& target = request.rowSink ? band : image;
        const int targetOffset = request.rowSink ? bandStart : 0;
        std::atomic<int> nextRow{bandStart};
        auto work = [&](int id) {
            RayCounts& local = perThread[id];
            std::uint64_t raysBefore = local.total();
            for (int row; (row = nextRow.fetch_add(1)) < bandStart + rows;) {
                if (request.cancel && request.cancel->load()) return;
                const int y = area.y0 + row;
                for (int column = 0; column < width; ++column) {
                    const int x = area.x0 + column;
                    const Pixel pixel = renderPixel(request, x, y, local);
                    const dvec3 c = pixel.colour;
                    TruncationReport& t = truncation[id];
                    const PixelTruncation outcome = pixel.truncation(x, y);
                    t.add(outcome);
                    t.deepest = std::max(t.deepest, pixel.deepest);
                    request.recordTruncation(static_cast<std::size_t>(row) * width + column, outcome);
                    float* p = target.pixel(column, row - targetOffset);
                    p[0] = static_cast<float>(c.x);
                    p[1] = static_cast<float>(c.y);
                    p[2] = static_cast<float>(c.z);
                }
                const int done = rowsDone.fetch_add(1) + 1;
                const std::uint64_t rays = raysTraced.fetch_add(local.total() - raysBefore) + local.total() - raysBefore;
                raysBefore = local.total();
                if (request.progress) request.progress(static_cast<double>(done) / height, rays);
            }
        };
        std::vector<std::thread> pool;
        for (int t = 1; t < threads; ++t) pool.emplace_back(work, t);
        work(0);
        for (std::thread& t : pool) t.join();
        if (request.cancel && request.cancel->load()) break;
        if (request.rowSink) request.rowSink(band.rgb.data(), rows);
    }
    if (request.truncation) {
        *request.truncation = TruncationReport{};
        for (const TruncationReport& t : truncation) request.truncation->merge(t);
    }
    if (counts) {
        *counts = RayCounts{};
        for (const RayCounts& c : perThread) {
            counts->primary += c.primary;
            counts->shadow += c.shadow;
            counts->reflected += c.reflected;
            counts->refracted += c.refracted;
        }
    }
    return image;
}

}  // namespace snell
