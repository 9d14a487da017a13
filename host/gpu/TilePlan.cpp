#include "gpu/TilePlan.h"

#include <thread>

#include "render/WorkgroupSchedule.h"

namespace snell::gpu {

namespace {

// Device memory for the invocations' ray stacks: 64 MiB on a CPU device; on
// a GPU a sixteenth of its memory, up to 1 GiB, for up to kGpuInvocations
// invocations. On an H200 at 2048², 64 MiB left SphereFlake2 (8.5 KB of
// stack an invocation at --depth 64) 7 872 invocations and took 1590 ms,
// 1 GiB 126 336 and 735 ms; showcase took 42 ms with 2^18 invocations and
// 212 with a million (every pixel of the tile its own), tir 78 and 344.
// 2^18 fills an H200 (132 multiprocessors of 2048 threads). (Where it
// lost: scenes/glass 20.7 → 38.2 ms with 13 000 → 210 000;
// docs/log/real-gpu.md, "On a real GPU: an NVIDIA H200".)
constexpr VkDeviceSize kStackBudget = 64ull << 20;
constexpr VkDeviceSize kGpuStackBudget = 1ull << 30;
constexpr VkDeviceSize kGpuInvocations = 1ull << 18;
// Workgroups of persistent invocations per core on a CPU device (lavapipe):
// enough that the cores finish together.
constexpr unsigned kCpuWorkgroupsPerCore = 8;

// Of `size` columns (rows) dealt in runs of `run` to `tiles` tiles in turn,
// those of tile `t`: `run` of each full round, then what the last round
// leaves for its run.
int dealtTo(int t, int tiles, int size, int run) {
    const int round = run * tiles;
    return size / round * run + std::clamp(size % round - t * run, 0, run);
}

}  // namespace

bool interleaves(const PixelWindow& area) {
    return (area.width() > kMaxTileSide || area.height() > kMaxTileSide) && area.width() <= kMaxInterleavedSide &&
           area.height() <= kMaxInterleavedSide;
}

int imageColumn(const TileParams& tile, std::uint32_t x) {
    const std::uint32_t run = SNELL_TILE_COLUMN_RUN, inRun = x % run;
    return int(tile.originX + (x - inRun) * tile.strideX + inRun);
}

int imageRow(const TileParams& tile, std::uint32_t y) {
    const std::uint32_t run = SNELL_TILE_ROW_RUN, inRun = y % run;
    return int(tile.originY + (y - inRun) * tile.strideY + inRun);
}

TilePlan::TilePlan(const PixelWindow& window, bool interleave) : area(window) {
    tilesX = (area.width() + kMaxTileSide - 1) / kMaxTileSide;
    tilesY = (area.height() + kMaxTileSide - 1) / kMaxTileSide;
    interleaved = interleave && interleaves(area);
    tileWidth = interleaved ? tile(0, 0).width : std::min(kMaxTileSide, area.width());
    tileHeight = interleaved ? tile(0, 0).height : std::min(kMaxTileSide, area.height());
}

TileParams TilePlan::tile(int tx, int ty) const {
    TileParams t{};
    if (interleaved) {
        t.originX = std::uint32_t(area.x0 + tx * SNELL_TILE_COLUMN_RUN);
        t.originY = std::uint32_t(area.y0 + ty * SNELL_TILE_ROW_RUN);
        t.width = std::uint32_t(dealtTo(tx, tilesX, area.width(), SNELL_TILE_COLUMN_RUN));
        t.height = std::uint32_t(dealtTo(ty, tilesY, area.height(), SNELL_TILE_ROW_RUN));
        t.strideX = std::uint32_t(tilesX);
        t.strideY = std::uint32_t(tilesY);
    } else {
        t.originX = std::uint32_t(area.x0 + tx * tileWidth);
        t.originY = std::uint32_t(area.y0 + ty * tileHeight);
        t.width = std::uint32_t(std::min(tileWidth, area.width() - tx * tileWidth));
        t.height = std::uint32_t(std::min(tileHeight, area.height() - ty * tileHeight));
        t.strideX = t.strideY = 1;
    }
    t.workgroupStride = workgroupStride;
    return t;
}

std::vector<RenderRegion> tileRegions(const PixelWindow& area, bool interleaved) {
    const TilePlan plan(area, interleaved);
    const double areaPixels = double(area.width()) * area.height();
    std::vector<RenderRegion> out;
    for (int ty = 0; ty < plan.tilesY; ++ty)
        for (int tx = 0; tx < plan.tilesX; ++tx) {
            const TileParams t = plan.tile(tx, ty);
            if (plan.interleaved)
                out.push_back({area, double(t.width) * t.height / areaPixels});
            else
                out.push_back({{int(t.originX), int(t.originY), int(t.originX + t.width), int(t.originY + t.height)}, 1.0});
        }
    return out;
}

TilePlan planTiles(const vk::Context& context, const RenderRequest& request, const Specialisation& values,
                   bool wide, bool planForCpu) {
    TilePlan plan(request.area(), request.interleavedTiles);
    // Persistent invocations (trace.comp): on a CPU device a few workgroups
    // per core keep every core busy to the end of the dispatch; on a GPU
    // enough to fill it, as many as the memory for their ray stacks allows.
    // Fp64 keeps a low part per pending ray too.
    const VkDeviceSize rayEntries = VkDeviceSize(values[SNELL_SPEC_RAY_STACK]) + values[SNELL_SPEC_FRONTIER];
    const VkDeviceSize bytesPerSlot =
        sizeof(SlotState) + rayEntries * ((wide ? 2 : 1) * sizeof(PendingRay) + values[SNELL_SPEC_MAX_MEDIA] * 4);
    const VkDeviceSize limit = context.properties().limits.maxStorageBufferRange;
    const bool cpu = planForCpu;
    const VkDeviceSize budget =
        cpu ? kStackBudget : std::clamp(context.deviceLocalBytes() / 16, kStackBudget, kGpuStackBudget);
    VkDeviceSize slots = std::min(budget, limit) / bytesPerSlot;
    if (cpu)
        slots = std::min<VkDeviceSize>(slots, SNELL_WORKGROUP_SIZE * kCpuWorkgroupsPerCore *
                                                  std::max(1u, std::thread::hardware_concurrency()));
    else
        slots = std::min(slots, kGpuInvocations);
    plan.invocations =
        std::clamp<VkDeviceSize>(std::min(slots, plan.tilePixels()) / SNELL_WORKGROUP_SIZE, 1, 65535) *
        SNELL_WORKGROUP_SIZE;
    // lavapipe gives each thread a contiguous range of workgroups: the shares
    // of neighbouring workgroups are spread over the tile (schedule/dispatch.glsl, share).
    if (cpu) plan.workgroupStride = spreadingStride(std::uint32_t(plan.workgroups()));
    plan.helps = values[SNELL_SPEC_HELPS] != 0;
    return plan;
}

}  // namespace snell::gpu
