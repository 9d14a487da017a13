#include "gpu/TileDispatch.h"

#include <atomic>
#include <cstring>

#include "common/Clock.h"

namespace snell::gpu {

using vk::check;

namespace {

void memoryBarrier(VkCommandBuffer cmd, VkAccessFlags srcAccess, VkAccessFlags dstAccess, VkPipelineStageFlags srcStage,
                   VkPipelineStageFlags dstStage) {
    VkMemoryBarrier b{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
    b.srcAccessMask = srcAccess;
    b.dstAccessMask = dstAccess;
    vkCmdPipelineBarrier(cmd, srcStage, dstStage, 0, 1, &b, 0, nullptr, 0, nullptr);
}

// The dispatch's counters, then each workgroup's, then the bits of the
// shares with pixels left and those of their words (shared_layout.h).
std::size_t shareBitsAt(std::uint64_t workgroups) { return SNELL_SHARE_BITS_AT(workgroups); }
std::size_t shareWords(std::uint64_t workgroups) { return SNELL_SHARE_WORDS(workgroups); }
std::size_t wordBitsAt(std::uint64_t workgroups) { return SNELL_WORD_BITS_AT(workgroups); }
std::size_t counterCount(std::uint64_t workgroups) { return SNELL_COUNTERS_FOR(workgroups); }
// Bits 0..n-1 set in words from counters[at] on.
void setBits(std::uint32_t* counters, std::size_t at, std::uint64_t n) {
    for (std::uint64_t i = 0; i < n; i += 32) counters[at + i / 32] = n - i >= 32 ? ~0u : (1u << (n - i)) - 1u;
}

// Waits for the submission, waking a few times a second for progress.whileRunning.
void waitFor(VkDevice device, VkFence fence, RenderProgress& progress) {
    for (;;) {
        constexpr std::uint64_t kPollNs = 100'000'000;
        const VkResult waited =
            vkWaitForFences(device, 1, &fence, VK_TRUE, progress.whileRunning ? kPollNs : UINT64_MAX);
        if (waited != VK_TIMEOUT) {
            check(waited, "vkWaitForFences");
            break;
        }
        progress.whileRunning();
    }
    check(vkResetFences(device, 1, &fence), "vkResetFences");
}

// The dispatch's counters into `result` and the truncation report.
void addCounters(const std::uint32_t* counters, bool countRays, bool countLanes, RenderProgress& progress,
                 GpuRenderResult& result) {
    progress.truncation.deepest = std::max(progress.truncation.deepest, int(counters[SNELL_COUNTER_DEEPEST]));
    result.stackOverflows += counters[SNELL_COUNTER_OVERFLOW];
    if (countLanes) {
        result.lanes.traceSlots += counters[SNELL_COUNTER_TRACE_SLOTS];
        result.lanes.traceBusy += counters[SNELL_COUNTER_TRACE_BUSY];
        result.lanes.walkSlots += counters[SNELL_COUNTER_WALK_SLOTS];
        result.lanes.walkBusy += counters[SNELL_COUNTER_WALK_BUSY];
    }
    if (countRays) {
        result.rays.primary += counters[SNELL_COUNTER_PRIMARY];
        result.rays.shadow += counters[SNELL_COUNTER_SHADOW];
        result.rays.reflected += counters[SNELL_COUNTER_REFLECTED];
        result.rays.refracted += counters[SNELL_COUNTER_REFRACTED];
    }
}

}  // namespace

void submit(vk::Context& context, Kernel& k, RenderProgress& progress, bool timed, bool resumes,
            const std::function<void(VkCommandBuffer)>& record) {
    VkDevice device = context.device();
    VkCommandBuffer cmd = k.commands;
    check(vkResetCommandBuffer(cmd, 0), "vkResetCommandBuffer");
    VkCommandBufferBeginInfo begin{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
    begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
    check(vkBeginCommandBuffer(cmd, &begin), "vkBeginCommandBuffer");
    if (resumes)
        memoryBarrier(cmd, VK_ACCESS_SHADER_WRITE_BIT, VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT,
                      VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT);
    if (timed && k.queries) {
        vkCmdResetQueryPool(cmd, k.queries, 0, 2);
        vkCmdWriteTimestamp(cmd, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, k.queries, 0);
    }
    record(cmd);
    if (timed && k.queries) vkCmdWriteTimestamp(cmd, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, k.queries, 1);
    check(vkEndCommandBuffer(cmd), "vkEndCommandBuffer");
    const auto start = Clock::now();
    VkSubmitInfo info{VK_STRUCTURE_TYPE_SUBMIT_INFO};
    info.commandBufferCount = 1;
    info.pCommandBuffers = &cmd;
    check(context.submit(info, k.fence), "vkQueueSubmit");
    waitFor(device, k.fence, progress);
    if (!timed) return;
    progress.hostMs += msSince(start);
    if (k.queries) {
        std::uint64_t stamps[2] = {0, 0};
        check(vkGetQueryPoolResults(device, k.queries, 0, 2, sizeof stamps, stamps, sizeof(std::uint64_t),
                                    VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT),
              "vkGetQueryPoolResults");
        progress.gpuMs += double(stamps[1] - stamps[0]) * context.properties().limits.timestampPeriod * 1e-6;
    }
}

void firstDispatch(vk::Context& context, Kernel& k) {
    const TileParams empty{};
    std::memset(k.counters.mapped, 0, SNELL_COUNTER_COUNT * sizeof(std::uint32_t));
    RenderProgress untimed;
    submit(context, k, untimed, false, false, [&](VkCommandBuffer cmd) {
        bindKernel(context, cmd, k);
        vkCmdPushConstants(cmd, k.layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof empty, &empty);
        vkCmdDispatch(cmd, 1, 1, 1);
    });
}

// A dispatch traces the tile; where the driver limits loops, the
// invocations suspend and the next dispatch resumes them, until none is left
// unfinished.
void dispatchTile(vk::Context& context, Kernel& k, const RenderRequest& request, const TilePlan& plan,
                  TileParams tile, bool countRays, bool countLanes, RenderProgress& progress,
                  GpuRenderResult& result) {
    auto* counters = static_cast<std::uint32_t*>(k.counters.mapped);
    const auto* states = static_cast<const SlotState*>(k.slotStates.mapped);
    const std::uint32_t groups = std::uint32_t(plan.invocations / SNELL_WORKGROUP_SIZE);
    if (request.progress) expectTileCost(request, plan, tile, progress);
    progress.whileRunning = [&] {
        if (request.cancel && request.cancel->load())
            std::atomic_ref<std::uint32_t>(counters[SNELL_COUNTER_CANCEL]).store(1u);
        reportProgress(states, counters, request, plan, tile, progress, false);
    };
    for (int pass = 0;; ++pass) {
        if (request.cancel && request.cancel->load()) throw vk::VulkanError("render cancelled");
        // A resumed dispatch goes on taking the workgroups' pixels where the last one stopped.
        std::memset(counters, 0, (pass > 0 ? SNELL_COUNTER_COUNT : counterCount(groups)) * sizeof(std::uint32_t));
        if (pass == 0) {
            setBits(counters, shareBitsAt(groups), groups);
            setBits(counters, wordBitsAt(groups), shareWords(groups));
        }
        tile.resume = pass > 0 ? 1u : 0u;
        if (pass == 0) std::memset(k.slotStates.mapped, 0, plan.invocations * sizeof(SlotState));
        submit(context, k, progress, true, pass > 0, [&](VkCommandBuffer cmd) {
            bindKernel(context, cmd, k);
            vkCmdPushConstants(cmd, k.layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof tile, &tile);
            vkCmdDispatch(cmd, groups, 1, 1);
            memoryBarrier(cmd, VK_ACCESS_SHADER_WRITE_BIT, VK_ACCESS_HOST_READ_BIT,
                          VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_PIPELINE_STAGE_HOST_BIT);
        });
        ++result.dispatches;
        if (counters[SNELL_COUNTER_LOOP_LIMIT] != 0)
            throw vk::VulkanError("a single ray needed more loop iterations than lavapipe allows in one "
                                  "dispatch (65535 per SIMD row); the image would be wrong. Try fewer "
                                  "lights or a smaller --depth");
        addCounters(counters, countRays, countLanes, progress, result);
        const std::uint32_t unfinished = counters[SNELL_COUNTER_UNFINISHED];
        if (request.cancel && request.cancel->load()) throw vk::VulkanError("render cancelled");
        reportProgress(states, counters, request, plan, tile, progress, unfinished == 0);
        if (unfinished == 0) break;
    }
    progress.whileRunning = nullptr;
}

}  // namespace snell::gpu
