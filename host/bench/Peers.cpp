// Peers on the shared bench scenes: the dispatch, the whole command, the CPU
// reference and POV-Ray, all tracing one tree; and POV-Ray's image against
// snell's where the two models agree.
#include "bench/BenchParts.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>

#include "bench/PovExport.h"
#include "common/Clock.h"
#include "image/ImageIO.h"
#include "reference/CpuRenderer.h"
#include "scene/Parser.h"

namespace snell::bench {

namespace {

// snell's dispatch: the median of `runs` after a warm-up; its first image,
// for POV-Ray's to be held to.
double timeDispatch(vk::Context& context, const Scene& scene, const RenderRequest& request, int runs,
                    Image& image) {
    ComputeRenderer renderer(context, scene, request.camera);
    renderer.render(request, false);
    std::vector<double> ms;
    for (int k = 0; k < runs; ++k) {
        GpuRenderResult g = renderer.render(request, false);
        ms.push_back(g.renderMs);
        if (k == 0) image = std::move(g.image);
    }
    return stats(ms).median;
}

// The whole `snell render` command: its first image with no kept kernel
// (cold; not in a quick run, where that compile would be a tenth of the
// run), the next (warm), then the median of `runs`.
void timeCommand(const BenchOptions& o, const SceneFile& file, int size, int runs, Peer& peer) {
    const std::string output = (fs::path(o.outDir) / "peer.png").string();
    const std::string common = quote(file.path) + " --size " + std::to_string(size) + " --depth " +
                               std::to_string(kPeerDepth) + " --min-weight 0 --spp 1 -q -o " + quote(output);
    const std::string cache = (fs::path(o.outDir) / "pipeline-cache").string();
    fs::remove_all(cache);
    const std::string command = "SNELL_CACHE_DIR=" + quote(cache) + " " + quote(o.snellPath) + " render " + common;
    if (!o.quick) peer.coldMs = runCommand(command);
    peer.warmMs = runCommand(command);
    std::vector<double> ms;
    for (int k = 0; k < runs; ++k) ms.push_back(runCommand(command));
    peer.snellCommandMs = stats(ms).median;
    fs::remove_all(cache);
    fs::remove(output);
}

// POV-Ray's trace time as it prints it, "Trace Time: ... (0.161 seconds)",
// in ms, and the step it is printed to.
double povTraceMs(const std::string& text, double& stepMs) {
    const std::size_t at = text.find("Trace Time:");
    const std::size_t open = at == std::string::npos ? at : text.find('(', at);
    if (open == std::string::npos) throw BenchError("POV-Ray printed no trace time");
    const char* number = text.c_str() + open + 1;
    const char* p = number;
    while (std::isdigit(static_cast<unsigned char>(*p))) ++p;
    int decimals = 0;
    if (*p == '.')
        while (std::isdigit(static_cast<unsigned char>(p[1 + decimals]))) ++decimals;
    stepMs = 1000.0 * std::pow(10.0, -decimals);
    return std::atof(number) * 1000.0;
}

// POV-Ray on the scene, as snell traces it (PovExport.h), writing linear
// values (File_Gamma=1.0) as SPEC's images are: its trace and command times,
// its image at `image`. The scene it traced stays in the output directory.
void timePovRay(const BenchOptions& o, const Scene& scene, int size, int runs, const std::string& image,
                Peer& peer) {
    const std::string pov = (fs::path(o.outDir) / (scene.name + ".pov")).string();
    std::ofstream(pov) << toPovRay(scene, kPeerDepth);
    const std::string command = "povray +I" + quote(pov) + " +O" + quote(image) + " +W" + std::to_string(size) +
                                " +H" + std::to_string(size) + " -D -A +Q9 +WT2 File_Gamma=1.0";
    std::vector<double> trace, whole;
    for (int k = 0; k < std::max(3, runs / 2); ++k) {
        std::string text;
        whole.push_back(runCommand(command, &text));
        trace.push_back(povTraceMs(text, peer.povTraceResolutionMs));
    }
    peer.povTraceMs = stats(trace).median;
    peer.povCommandMs = stats(whole).median;
}

bool colouredHighlights(const Scene& scene) {
    for (const Sphere& s : scene.spheres) {
        const dvec3 ks = scene.materials[s.material].ks;
        if (ks.x != ks.y || ks.y != ks.z) return true;
    }
    return false;
}

// POV-Ray's image against snell's and the CPU reference's, where the models agree.
PovAgreement compareWithPovRay(const Scene& scene, const std::string& povImage, const Image& snellImage,
                               const Image& cpuImage) {
    PovAgreement a;
    if (!povModelAgrees(scene)) {
        a.note = "not compared: transparent spheres (POV-Ray's shadows pass through them, SPEC's do not)";
        return a;
    }
    a.compared = true;
    const Image pov = readImage(povImage);
    a.metrics = compareImages(pov, snellImage);
    a.cpuMetrics = compareImages(pov, cpuImage);
    a.agrees = a.metrics.meanAbsError <= 0.5 && a.metrics.badFraction <= 0.001;
    if (colouredHighlights(scene)) a.note = "coloured ks: POV-Ray's highlight has one strength, their mean";
    return a;
}

}  // namespace

std::string describe(const PovAgreement& a) {
    if (!a.compared) return a.note;
    std::ostringstream s;
    s.precision(2);
    const ImageMetrics& m = a.metrics;
    s << "mean " << std::fixed << m.meanAbsError << "/255, max " << m.maxError << "/255, " << m.badPixels
      << (m.badPixels == 1 ? " pixel (" : " pixels (") << 100.0 * m.badFraction
      << " %) over 3/255: " << (a.agrees ? "agrees" : "differs") << " (the CPU reference's: mean "
      << a.cpuMetrics.meanAbsError << "/255, max " << a.cpuMetrics.maxError << "/255)";
    if (!a.note.empty()) s << "; " << a.note;
    return s.str();
}

// Peers on the shared bench scenes, at the scene's own size (quick: the
// bench's): the same tree for each (kPeerDepth, no cut-off, one ray a pixel).
Peer measurePeer(vk::Context& context, const BenchOptions& o, const SceneFile& file, const Scene& scene,
                 const CpuRenderer& cpu, const RenderRequest& base, int runs, std::ostream& log) {
    Peer peer;
    peer.scene = file.group + "/" + scene.name;
    peer.size = o.quick ? base.width : scene.imageSize;
    RenderRequest request = base;
    request.width = request.height = peer.size;
    request.camera = Camera::fromSpec(peer.size, scene.halfWidth);
    request.supersample = 1;  // POV-Ray traces one ray a pixel (-A)
    request.trace.maxDepth = kPeerDepth;
    request.trace.minWeight = 0.0;
    request.trace.tolerance = 0.0;
    Image snellImage;
    peer.snellDispatchMs = timeDispatch(context, scene, request, runs, snellImage);
    const auto start = Clock::now();
    const Image cpuImage = cpu.render(request);
    peer.cpu = timeCpu([&] { cpu.render(request); }, msSince(start), runs);
    if (!o.snellPath.empty()) timeCommand(o, file, peer.size, runs, peer);
    if (std::system("command -v povray >/dev/null 2>&1") == 0) {
        const std::string povImage = (fs::path(o.outDir) / "pov.png").string();
        try {
            timePovRay(o, scene, peer.size, runs, povImage, peer);
            peer.agreement = compareWithPovRay(scene, povImage, snellImage, cpuImage);
        } catch (const std::exception& e) {  // BenchError, ImageIOError
            peer.povNote = e.what();
        }
        fs::remove(povImage);
    } else {
        peer.povNote = "povray is not installed (apt-get install povray)";
    }
    log << "  peers at " << peer.size << "x" << peer.size << ", depth " << kPeerDepth
        << " (POV-Ray's max_trace_level " << povTraceLevel(kPeerDepth) << "), one ray a pixel: snell dispatch "
        << number(peer.snellDispatchMs) << " ms, command " << number(peer.snellCommandMs) << " ms (first image"
        << (o.quick ? "" : " cold " + number(peer.coldMs) + ",") << " warm " << number(peer.warmMs)
        << "); CPU reference " << describe(peer.cpu) << "; POV-Ray ";
    if (peer.povTraceMs) {
        log << "trace " << number(*peer.povTraceMs) << " ms (printed to " << number(peer.povTraceResolutionMs)
            << " ms), command " << number(*peer.povCommandMs) << " ms; snell's dispatch "
            << ratioText(*peer.povTraceMs, peer.povTraceResolutionMs / 2, peer.snellDispatchMs)
            << " faster than its trace; its image against snell's: " << describe(peer.agreement) << "\n";
    } else {
        log << peer.povNote << "\n";
    }
    return peer;
}

}  // namespace snell::bench
