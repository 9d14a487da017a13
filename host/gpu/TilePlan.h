// How a render covers its window: tiles of at most kMaxTileSide² pixels (16
// MiB of float image), each traced by the same persistent invocations,
// interleaved up to kMaxInterleavedSide, else blocks; and how many
// invocations trace them.
#pragma once

#include <algorithm>
#include <cstdint>
#include <vector>

#include "gpu/KernelPolicy.h"
#include "render/RenderRequest.h"
#include "vulkan/VulkanContext.h"

namespace snell::gpu {

// The largest tile side: an image is rendered (and streamed) tile by tile.
constexpr int kMaxTileSide = 1024;
// Up to this side, where asked (RenderRequest::interleavedTiles), a window of
// more than one tile is cut into interleaved tiles (ComputeRenderer.h).
constexpr int kMaxInterleavedSide = 2 * kMaxTileSide;
bool interleaves(const PixelWindow& area);

// The image's column and row of the tile's column x and row y (TileParams;
// schedule/pixels.glsl, imagePixel).
int imageColumn(const TileParams& tile, std::uint32_t x);
int imageRow(const TileParams& tile, std::uint32_t y);

struct TilePlan {
    PixelWindow area;  // the window rendered; pixel coordinates stay the whole image's
    int tileWidth = 0, tileHeight = 0, tilesX = 0, tilesY = 0;  // the largest tile's size
    bool interleaved = false;  // tile (i, j): every tilesX-th run of columns from run i, and so rows (TileParams)
    VkDeviceSize invocations = 0;
    std::uint32_t workgroupStride = 1;  // TileParams::workgroupStride
    // Whether workgroups help with each other's shares once theirs is taken
    // (SNELL_SPEC_HELPS): then what a workgroup finished is not its share's.
    bool helps = false;

    TilePlan(const PixelWindow& window, bool interleave);
    int count() const { return tilesX * tilesY; }
    // The rows streamed at a time: a row of blocks, or the whole of interleaved tiles.
    int bandRows() const { return interleaved ? area.height() : tileHeight; }
    std::uint64_t workgroups() const { return invocations / SNELL_WORKGROUP_SIZE; }
    // The share of the tile's pixels workgroup w takes (schedule/pixels.glsl, takePixel).
    std::uint64_t shareOf(std::uint64_t w) const { return w * workgroupStride % workgroups(); }
    VkDeviceSize tilePixels() const { return VkDeviceSize(tileWidth) * tileHeight; }
    // Tile (tx, ty): where it is, and how an invocation steps through it.
    TileParams tile(int tx, int ty) const;
};

// The tiles of `area`, in the order they are traced, with the share of the
// window's pixels each holds.
std::vector<RenderRegion> tileRegions(const PixelWindow& area, bool interleaved);

// The plan for `request`: persistent invocations as many as the device keeps
// busy and the memory for their stacks (sized by `values`) allows.
TilePlan planTiles(const vk::Context& context, const RenderRequest& request, const Specialisation& values,
                   bool wide, bool planForCpu);

}  // namespace snell::gpu
