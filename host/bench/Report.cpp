// The report: bench.csv and bench.json.
#include "bench/BenchParts.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include <fstream>

#include "bench/PovExport.h"
#include "common/Json.h"

namespace snell::bench {

// bench.csv: one row per scene and setting; the price of the default (and
// the default's pixels by how they stopped) on the default's row.
void writeCsv(const fs::path& path, const Collected& c, const Ceiling& ceiling) {
    std::map<std::string, const Price*> priceOfScene;
    for (const Price& p : c.prices) priceOfScene[p.scene] = &p;
    std::ofstream csv(path);
    csv << "scene,setting,precision,bvh,depth,min_weight,supersample,size,spheres,dispatch_ms_median,"
           "dispatch_ms_min,dispatch_ms_max,timing,rays_primary,rays_shadow,rays_reflected,rays_refracted,"
           "rays_per_s,mean_abs_error,rmse,psnr,bad_fraction,max_error,non_finite,ceiling_fraction,failure,"
           "bad_pixels,front,price,price_is_upper_bound,price_setting,pixels_certified,pixels_estimated,"
           "pixels_unbounded_not_estimated\n";
    for (const Result& r : c.results) {
        const double raysPerSecond = r.dispatchMs.median > 0 ? r.rays.total() / (r.dispatchMs.median * 1e-3) : 0;
        // Ray–sphere tests a second without a BVH, against the micro-kernel.
        const double ceilingFraction =
            r.bvhUsed || r.dispatchMs.median <= 0
                ? NAN
                : (double(r.rays.total()) * r.spheres / (r.dispatchMs.median * 1e-3)) / ceiling.centreRadius;
        csv << r.scene << ",\"" << r.setting.name << "\","
            << (r.setting.precision == gpu::Precision::Fp64 ? "fp64" : "fp32") << ","
            << (r.bvhUsed ? "on" : "off") << "," << r.setting.depth << "," << r.setting.minWeight << ","
            << r.supersample << "," << r.size << "," << r.spheres << "," << number(r.dispatchMs.median) << ","
            << number(r.dispatchMs.min) << "," << number(r.dispatchMs.max) << ","
            << (r.gpuTimed ? "gpu" : "host") << "," << r.rays.primary << "," << r.rays.shadow << ","
            << r.rays.reflected << "," << r.rays.refracted << "," << number(raysPerSecond) << ","
            << number(r.error.meanAbsError) << "," << number(r.error.rmse) << "," << number(r.error.psnr) << ","
            << number(r.error.badFraction) << "," << r.error.maxError << "," << r.error.nonFinite << ","
            << (std::isnan(ceilingFraction) ? "" : number(ceilingFraction)) << ",\"" << r.failure << "\","
            << r.error.badPixels << "," << (r.setting.front ? 1 : 0) << ",";
        const auto p = priceOfScene.find(r.scene);
        if (r.setting.name == "default" && p != priceOfScene.end() && !std::isnan(p->second->price)) {
            const Price& price = *p->second;
            csv << number(price.price) << "," << (price.upperBound ? 1 : 0) << ",\"" << price.fixed << "\","
                << price.certified << "," << price.estimated << "," << price.unboundedNotEstimated << "\n";
        } else {
            csv << ",,,,,\n";
        }
    }
}

void writeResultJson(std::ostream& json, const Result& r, const Collected& c) {
    json << "    {\"scene\": " << jsonString(r.scene) << ", \"setting\": " << jsonString(r.setting.name)
         << ", \"precision\": \"" << (r.setting.precision == gpu::Precision::Fp64 ? "fp64" : "fp32")
         << "\", \"bvh\": " << (r.bvhUsed ? "true" : "false") << ", \"depth\": " << r.setting.depth
         << ", \"min_weight\": " << number(r.setting.minWeight) << ", \"supersample\": " << r.supersample
         << ", \"spheres\": " << r.spheres << ", \"dispatch_ms\": {\"median\": " << number(r.dispatchMs.median)
         << ", \"min\": " << number(r.dispatchMs.min) << ", \"max\": " << number(r.dispatchMs.max)
         << "}, \"rays\": {\"primary\": " << r.rays.primary << ", \"shadow\": " << r.rays.shadow
         << ", \"reflected\": " << r.rays.reflected << ", \"refracted\": " << r.rays.refracted
         << "}, \"error\": " << r.error.json() << ", \"tolerance\": " << number(r.setting.tolerance)
         << ", \"front\": " << (r.setting.front ? "true" : "false")
         << ", \"stated_bound\": {\"max\": " << number(255.0 * r.bound.maxBound)
         << ", \"mean\": " << number(255.0 * r.bound.meanBound()) << ", \"unbounded_pixels\": " << r.bound.unbounded
         << ", \"estimated_pixels\": " << r.bound.estimated << ", \"over_tolerance_pixels\": "
         << r.bound.overTolerance << ", \"over_budget_pixels\": " << r.bound.overBudget << "}"
         << ", \"reference_ms\": " << number(c.referenceMs.at(r.scene).ms.median)
         << ", \"reference_runs\": " << c.referenceMs.at(r.scene).runs
         << ", \"cpu_default_ms\": " << number(c.cpuDefaultMs.at(r.scene).ms.median)
         << ", \"cpu_default_runs\": " << c.cpuDefaultMs.at(r.scene).runs
         << ", \"failure\": " << jsonString(r.failure) << "}";
}

void writePriceJson(std::ostream& json, const Price& p) {
    json << "    {\"scene\": " << jsonString(p.scene) << ", \"default_ms\": " << number(p.defaultMs)
         << ", \"default_mean_abs_error\": " << number(p.defaultMean) << ", \"default_bad_pixels\": " << p.defaultBad
         << ", \"price\": " << number(p.price) << ", \"price_is_upper_bound\": " << (p.upperBound ? "true" : "false")
         << ", \"fixed_setting\": " << (p.fixed.empty() ? "null" : jsonString(p.fixed))
         << ", \"fixed_ms\": " << number(p.fixedMs) << ", \"fixed_mean_abs_error\": " << number(p.fixedMean)
         << ", \"fixed_bad_pixels\": " << p.fixedBad << ", \"fixed_tried\": " << p.tried
         << ", \"side_by_side_runs\": " << p.sideBySideRuns
         << ", \"pixels\": {\"total\": " << p.pixels << ", \"certified\": " << p.certified
         << ", \"estimated\": " << p.estimated << ", \"unbounded_not_estimated\": " << p.unboundedNotEstimated
         << ", \"over_tolerance\": " << p.overTolerance << ", \"over_budget\": " << p.overBudget << "}}";
}

void writePriceSummaryJson(std::ostream& json, const PriceSummary& s) {
    json << "{\"geometric_mean\": " << number(s.geometricMean) << ", \"scenes\": " << s.scenes
         << ", \"upper_bounds\": " << s.upperBounds
         << ", \"worst_scene\": " << (s.worst ? jsonString(s.worst->scene) : "null")
         << ", \"worst_price\": " << (s.worst ? number(s.worst->price) : "null")
         << ", \"worst_is_upper_bound\": " << (s.worst && s.worst->upperBound ? "true" : "false")
         << ", \"worst_fixed_setting\": " << (s.worst ? jsonString(s.worst->fixed) : "null") << "}";
}

void writePeerJson(std::ostream& json, const Peer& p) {
    const PovAgreement& a = p.agreement;
    json << "    {\"scene\": " << jsonString(p.scene) << ", \"size\": " << p.size << ", \"depth\": " << kPeerDepth
         << ", \"povray_max_trace_level\": " << povTraceLevel(kPeerDepth) << ", \"samples_per_pixel\": 1"
         << ", \"snell_dispatch_ms\": " << number(p.snellDispatchMs)
         << ", \"snell_command_ms\": " << number(p.snellCommandMs) << ", \"first_image_cold_ms\": "
         << number(p.coldMs) << ", \"first_image_warm_ms\": " << number(p.warmMs)
         << ", \"cpu_reference_ms\": " << number(p.cpu.ms.median) << ", \"cpu_reference_runs\": " << p.cpu.runs
         << ", \"povray_trace_ms\": " << (p.povTraceMs ? number(*p.povTraceMs) : "null")
         << ", \"povray_trace_resolution_ms\": " << (p.povTraceMs ? number(p.povTraceResolutionMs) : "null")
         << ", \"povray_command_ms\": " << (p.povCommandMs ? number(*p.povCommandMs) : "null")
         << ", \"note\": " << jsonString(p.povNote) << ", \"povray_agreement\": {\"compared\": "
         << (a.compared ? "true" : "false");
    // POV-Ray's image against snell's, in ImageMetrics' terms (1/255).
    if (a.compared)
        json << ", \"agrees\": " << (a.agrees ? "true" : "false") << ", \"error\": " << a.metrics.json()
             << ", \"cpu_reference_error\": " << a.cpuMetrics.json();
    json << ", \"note\": " << jsonString(a.note) << "}}";
}

// bench.json: everything, for tools.
void writeJson(const fs::path& path, const Collected& c, const Ceiling& ceiling, vk::Context& context,
               const std::string& device, int size, int runs) {
    std::ofstream json(path);
    json << "{\n  \"device\": " << jsonString(device) << ",\n  \"driver\": " << jsonString(context.driverInfo())
         << ",\n  \"size\": " << size << ",\n  \"runs\": " << runs
         << ",\n  \"timing\": \"" << (context.timestampsSupported() ? "gpu-timestamps" : "host") << "\""
         << ",\n  \"ceiling_tests_per_s\": {\"centre_radius\": " << number(ceiling.centreRadius)
         << ", \"inverse_matrix\": " << number(ceiling.matrix) << "},\n  \"floor\": {\"size\": "
         << ceiling.floorSize << ", \"store_kernel_ms\": " << number(ceiling.storeMs)
         << ", \"empty_scene_ms\": " << number(ceiling.emptySceneMs) << "},\n  \"results\": [\n";
    for (std::size_t i = 0; i < c.results.size(); ++i) {
        writeResultJson(json, c.results[i], c);
        json << (i + 1 < c.results.size() ? "," : "") << "\n";
    }
    json << "  ],\n  \"prices\": [\n";
    for (std::size_t i = 0; i < c.prices.size(); ++i) {
        writePriceJson(json, c.prices[i]);
        json << (i + 1 < c.prices.size() ? "," : "") << "\n";
    }
    json << "  ],\n  \"price_summary\": ";
    writePriceSummaryJson(json, summarizePrices(c.prices));
    json << ",\n  \"peers\": [\n";
    for (std::size_t i = 0; i < c.peers.size(); ++i) {
        writePeerJson(json, c.peers[i]);
        json << (i + 1 < c.peers.size() ? "," : "") << "\n";
    }
    json << "  ],\n  \"walk_floors\": [\n";
    for (std::size_t i = 0; i < c.walkFloors.size(); ++i) {
        const WalkFloor& w = c.walkFloors[i];
        json << "    {\"scene\": " << jsonString(w.scene) << ", \"size\": " << w.size
             << ", \"floor_kernel_ms\": " << number(w.floorMs) << ", \"floor_kernel_rays\": " << w.floorRays
             << ", \"floor_kernel_hits\": " << w.floorHits << ", \"floor_kernel_blocked\": " << w.floorBlocked
             << ", \"render_depth0_ms\": " << number(w.renderMs) << ", \"render_depth0_rays\": " << w.renderRays
             << "}" << (i + 1 < c.walkFloors.size() ? "," : "") << "\n";
    }
    json << "  ],\n  \"scaling\": [\n";
    for (std::size_t i = 0; i < c.scaling.size(); ++i) {
        const Scaling& s = c.scaling[i];
        json << "    {\"spheres\": " << s.spheres << ", \"size\": " << s.size << ", \"parse_ms\": "
             << number(s.parseMs) << ", \"bvh_build_ms\": " << number(s.bvhBuildMs)
             << ", \"upload_ms\": " << number(s.uploadMs) << ", \"render_ms\": {\"median\": "
             << number(s.renderMs.median) << ", \"min\": " << number(s.renderMs.min) << ", \"max\": "
             << number(s.renderMs.max) << "}, \"gpu_scene_mib\": " << number(s.gpuMiB)
             << ", \"peak_rss_mib\": " << number(s.peakRssMiB) << "}" << (i + 1 < c.scaling.size() ? "," : "")
             << "\n";
    }
    json << "  ]\n}\n";
}

}  // namespace snell::bench
