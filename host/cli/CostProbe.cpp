#include "cli/CostProbe.h"

#include <algorithm>
#include <numeric>
#include <optional>
#include <tuple>

#include "common/Clock.h"

namespace snell::cli {

double estimateCost(const Scene& scene, const RenderRequest& request, const std::vector<RenderRegion>& regions,
                    Progress& progress, double& estimateMs, const ProbeRender& render, CostMap* map) {
    constexpr int kStride = 16;
    constexpr double kMinCameraRays = 1 << 16;
    const PixelWindow area = request.area();
    const double cameraRays = double(area.width()) * area.height() * request.supersample * request.supersample;
    if (cameraRays < kMinCameraRays) return 0.0;
    RenderRequest probe;
    probe.width = probe.height = std::max(1, request.width / kStride);
    probe.camera = Camera::fromSpec(probe.width, scene.halfWidth);
    probe.supersample = request.supersample;
    probe.trace = request.trace;
    probe.cancel = request.cancel;
    const auto start = Clock::now();
    std::vector<double> seconds, rays;
    std::vector<float> pixelRays;
    if (map) *map = CostMap{kStride, probe.width, probe.height, std::vector<float>(std::size_t(probe.width) * probe.height)};
    std::optional<PixelWindow> last;
    double windowMs = 0.0, windowRays = 0.0, scale = 0.0;
    for (const RenderRegion& region : regions) {
        const PixelWindow& r = region.window;
        if (last != r) {
            last = r;
            const int x0 = std::min(r.x0 / kStride, probe.width - 1), y0 = std::min(r.y0 / kStride, probe.height - 1);
            probe.window = {x0, y0, std::max(r.x1 / kStride, x0 + 1), std::max(r.y1 / kStride, y0 + 1)};
            // In the render's own terms: the probe saw one pixel in (its share of) the window's.
            const PixelWindow seen = probe.area();
            scale = double(r.width()) * r.height() / (double(seen.width()) * seen.height());
            probe.rayImage = map ? &pixelRays : nullptr;
            std::tie(windowMs, windowRays) = render(probe);
            if (map && pixelRays.size() == std::size_t(seen.width()) * seen.height())
                for (int y = 0; y < seen.height(); ++y)
                    std::copy_n(pixelRays.begin() + std::ptrdiff_t(y) * seen.width(), seen.width(),
                                map->cells.begin() + std::ptrdiff_t(seen.y0 + y) * map->width + seen.x0);
        }
        seconds.push_back(1e-3 * windowMs * scale * region.share);
        rays.push_back(windowRays * scale * region.share);
    }
    estimateMs += msSince(start);
    if (map && std::all_of(map->cells.begin(), map->cells.end(), [](float c) { return c == 0.0f; })) *map = {};
    // Regions that share one window are its interleaved tiles: alike.
    const bool alike = regions.size() > 1 && std::all_of(regions.begin(), regions.end(), [&](const RenderRegion& r) {
        return r.window == regions[0].window;
    });
    progress.expectCost(seconds, rays, map && !map->empty(), alike);
    return std::accumulate(seconds.begin(), seconds.end(), 0.0);
}

std::vector<RenderRegion> rowBands(const PixelWindow& area) {
    constexpr int kBands = 32;
    std::vector<RenderRegion> bands;
    const int count = std::min(kBands, area.height());
    for (int b = 0; b < count; ++b)
        bands.push_back({{area.x0, area.y0 + area.height() * b / count, area.x1, area.y0 + area.height() * (b + 1) / count}});
    return bands;
}

}  // namespace snell::cli
