// Peers on the shared bench scenes: the dispatch, the whole command, the CPU reference, POV-Ray.
#include "bench/BenchParts.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include <fstream>

#include "bench/PovExport.h"
#include "common/Clock.h"
#include "image/ImageIO.h"
#include "reference/CpuRenderer.h"
#include "scene/Parser.h"

namespace snell::bench {

// Peers on the shared bench scenes: depth 5, no cut-off, at the scene's own
// size (quick: the bench's): the dispatch, the whole `snell render`
// command, the CPU reference and POV-Ray.
Peer measurePeer(vk::Context& context, const BenchOptions& o, const SceneFile& file, const Scene& scene,
                 const CpuRenderer& cpu, const RenderRequest& base, int runs, std::ostream& log) {
    Peer peer;
    peer.scene = file.group + "/" + scene.name;
    peer.size = o.quick ? base.width : scene.imageSize;
    RenderRequest request = base;
    request.width = request.height = peer.size;
    request.camera = Camera::fromSpec(peer.size, scene.halfWidth);
    request.trace.maxDepth = 5;
    request.trace.minWeight = 0.0;
    request.trace.tolerance = 0.0;
    {
        ComputeRenderer renderer(context, scene, request.camera);
        renderer.render(request, false);
        std::vector<double> ms;
        for (int k = 0; k < runs; ++k) ms.push_back(renderer.render(request, false).renderMs);
        peer.snellDispatchMs = stats(ms).median;
    }
    {
        const auto start = Clock::now();
        cpu.render(request);
        peer.cpuMs = msSince(start);
    }
    const std::string output = (fs::path(o.outDir) / "peer.png").string();
    const std::string common = quote(file.path) + " --size " + std::to_string(peer.size) +
                               " --depth 5 --min-weight 0 -q -o " + quote(output);
    if (!o.snellPath.empty()) {
        const std::string cache = (fs::path(o.outDir) / "pipeline-cache").string();
        fs::remove_all(cache);
        const std::string env = "SNELL_CACHE_DIR=" + quote(cache) + " ";
        peer.coldMs = runCommand(env + quote(o.snellPath) + " render " + common);
        peer.warmMs = runCommand(env + quote(o.snellPath) + " render " + common);
        std::vector<double> ms;
        for (int k = 0; k < runs; ++k) ms.push_back(runCommand(env + quote(o.snellPath) + " render " + common));
        peer.snellCommandMs = stats(ms).median;
        fs::remove_all(cache);
    }
    fs::remove(output);
    if (std::system("command -v povray >/dev/null 2>&1") == 0) {
        const std::string pov = (fs::path(o.outDir) / (scene.name + ".pov")).string();
        std::ofstream(pov) << toPovRay(scene, 5);
        const std::string povOut = (fs::path(o.outDir) / "pov.png").string();
        const std::string command = "povray +I" + quote(pov) + " +O" + quote(povOut) + " +W" +
                                    std::to_string(peer.size) + " +H" + std::to_string(peer.size) +
                                    " -D -A +Q9 +WT2";
        std::vector<double> trace, whole;
        try {
            for (int k = 0; k < std::max(3, runs / 2); ++k) {
                std::string text;
                whole.push_back(runCommand(command, &text));
                // "Trace Time:       0 hours  0 minutes  0 seconds (0.161 seconds)"
                const std::size_t at = text.find("Trace Time:");
                const std::size_t open = at == std::string::npos ? at : text.find('(', at);
                if (open == std::string::npos) throw BenchError("POV-Ray printed no trace time");
                trace.push_back(std::atof(text.c_str() + open + 1) * 1000.0);
            }
            peer.povTraceMs = stats(trace).median;
            peer.povCommandMs = stats(whole).median;
        } catch (const BenchError& e) {
            peer.povNote = e.what();
        }
        fs::remove(povOut);
        fs::remove(pov);
    } else {
        peer.povNote = "povray is not installed (apt-get install povray)";
    }
    log << "  peers at " << peer.size << "x" << peer.size << ", depth 5: snell dispatch "
        << number(peer.snellDispatchMs) << " ms, command " << number(peer.snellCommandMs) << " ms (cold "
        << number(peer.coldMs) << ", warm " << number(peer.warmMs) << "); CPU reference " << number(peer.cpuMs)
        << " ms; POV-Ray trace "
        << (peer.povTraceMs ? number(*peer.povTraceMs) + " ms, command " + number(*peer.povCommandMs) + " ms"
                            : peer.povNote)
        << "\n";
    return peer;
}

}  // namespace snell::bench
