#include "gpu/TileReadback.h"

#include <algorithm>
#include <cmath>

#include "common/Clock.h"

namespace snell::gpu {

namespace {

// The pixel's truncation, as the kernel reports it (shared_layout.h, OutputPixel).
PixelTruncation truncationOf(const OutputPixel& out, int imageX, int imageY) {
    PixelTruncation pixel;
    pixel.x = imageX;
    pixel.y = imageY;
    pixel.bound = std::abs(out.colour.a);  // negative where not finite
    pixel.unbounded = out.colour.a < 0.0f;
    pixel.overBudget = out.truncation.y != 0.0f;
    pixel.overTolerance = out.truncation.z != 0.0f;
    pixel.estimated = out.truncation.x >= 0.0f;
    if (pixel.estimated) pixel.estimatedError = out.truncation.x;  // the kernel reports no other estimate
    pixel.droppedGrowing = out.truncation.z == 2.0f;
    return pixel;
}

}  // namespace

void readBackTile(const OutputPixel* pixels, const RenderRequest& request, const TilePlan& plan,
                  const TileParams& tile, Image& rows, int firstRow, RenderProgress& progress,
                  GpuRenderResult& result) {
    const auto readStart = Clock::now();
    const PixelWindow& area = plan.area;
    TruncationReport& truncation = progress.truncation;
    for (std::uint32_t y = 0; y < tile.height; ++y) {
        const int imageY = imageRow(tile, y), windowRow = imageY - area.y0;
        float* row = rows.pixel(0, windowRow - firstRow);
        const OutputPixel* src = pixels + std::size_t(y) * tile.width;
        for (std::uint32_t x = 0; x < tile.width; ++x) {
            const OutputPixel& out = src[x];
            const int imageX = imageColumn(tile, x), column = imageX - area.x0;
            row[column * 3 + 0] = out.colour.r;
            row[column * 3 + 1] = out.colour.g;
            row[column * 3 + 2] = out.colour.b;
            const PixelTruncation pixel = truncationOf(out, imageX, imageY);
            truncation.add(pixel);
            request.recordTruncation(std::size_t(windowRow) * area.width() + column, pixel);
            if (request.rayImage)
                (*request.rayImage)[std::size_t(windowRow) * area.width() + column] = out.truncation.w;
        }
    }
    result.readbackMs += msSince(readStart);
    ++result.tiles;
    ++progress.tilesDone;
}

}  // namespace snell::gpu
