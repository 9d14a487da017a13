#include "render/Reach.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <cstdint>
#include <numeric>
#include <utility>

#include "render/Placement.h"

namespace snell {

namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();
// Sphere pairs the sweep compares before it takes every surface for one that
// may lie inside another.
constexpr double kMaxPairs = 1e8;
// The iteration's rounds: at most kMaxRounds, and kMaxUpdates sphere and
// pair updates a channel (about a millisecond); a scene that allows fewer
// than kMinRounds is not tried, and one whose changes do not halve in
// kCheckRounds is given up (light kept by a cycle of gain 1 grows by the same
// amount every round, for ever). Then the bound is R.
constexpr double kMaxUpdates = 1e5;
constexpr std::size_t kMaxRounds = 2000;
constexpr std::size_t kMinRounds = 20;
constexpr std::size_t kCheckRounds = 25;

// k times light, where a coefficient of 0 passes nothing, however much light.
double times(double k, double light) { return k == 0.0 ? 0.0 : k * light; }

// How far sphere s reaches from its centre along unit direction n: its
// radius, or for an ellipsoid |Mᵀn| (M its linear part).
double support(const Sphere& s, const glm::dvec3& n) {
    return s.isTrueSphere ? s.radius : glm::length(glm::transpose(glm::dmat3(s.worldFromObject)) * n);
}
glm::dvec3 centreOf(const Sphere& s) { return s.isTrueSphere ? s.centre : glm::dvec3(s.worldFromObject[3]); }

// Whether a plane across the line between their centres parts two spheres.
bool parted(const Sphere& a, const Sphere& b) {
    const glm::dvec3 d = centreOf(b) - centreOf(a);
    const double distance = glm::length(d);
    if (!(distance > 0.0)) return false;
    const glm::dvec3 n = d / distance;
    const double reach = support(a, n) + support(b, n);
    return reach < distance - 1e-9 * (distance + reach + glm::length(centreOf(a)) + glm::length(centreOf(b)));
}

// Pairs (a, b) where a's surface may lie inside b, by bounding balls (and a
// parting plane where one is an ellipsoid, whose ball says only where it is
// not); empty and `all` where the scene has too many to look at.
struct Overlaps {
    std::vector<std::pair<std::uint32_t, std::uint32_t>> pairs;
    bool all = false;
};
Overlaps overlaps(const Scene& scene) {
    const std::size_t n = scene.spheres.size();
    Overlaps o;
    std::vector<Ball> balls(n);
    std::vector<double> slack(n);
    for (std::size_t i = 0; i < n; ++i) {
        balls[i] = boundingBall(scene.spheres[i]);
        // Wider than placement()'s margin: pairs the sweep leaves out are apart.
        slack[i] = 2e-9 * (glm::length(balls[i].centre) + balls[i].radius) + 1e-300;
    }
    std::vector<std::uint32_t> order(n);
    std::iota(order.begin(), order.end(), 0u);
    auto low = [&](std::uint32_t i) { return balls[i].centre.x - balls[i].radius - slack[i]; };
    auto high = [&](std::uint32_t i) { return balls[i].centre.x + balls[i].radius + slack[i]; };
    std::sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) { return low(a) < low(b); });
    std::vector<std::uint32_t> active;
    double looked = 0.0;
    for (std::uint32_t a : order) {
        std::erase_if(active, [&](std::uint32_t b) { return high(b) < low(a); });
        looked += double(active.size());
        if (looked > kMaxPairs) return {{}, true};
        for (std::uint32_t b : active) {
            const Placement p = placement(balls[a], balls[b]);
            if (p == Placement::Apart) continue;
            const Sphere& sa = scene.spheres[a];
            const Sphere& sb = scene.spheres[b];
            const bool exact = sa.isTrueSphere && sb.isTrueSphere;
            if (!exact && parted(sa, sb)) continue;
            if (!exact || p != Placement::Around) o.pairs.push_back({a, b});
            if (!exact || p != Placement::Inside) o.pairs.push_back({b, a});
        }
        active.push_back(a);
    }
    return o;
}

// One channel of the bound: O (a ray leaving a sphere outwards) and J (a
// ray starting into it) for every sphere, each the most light its next hit
// returns: a hit on k from outside at most L_k + ks·O_k + kt·max(J_k, O_k)
// (refracted in, or totally reflected out), from inside at most
// L'_k + ks·J_k + kt·max(O_k, J_k). A ray leaving i meets any sphere but i
// from outside, or from inside one that i's surface may lie in, or nothing;
// a ray into i meets i from inside, or a sphere whose surface may lie in i.
// A hollow sphere's J is I (the header: no total internal reflection).
struct Channel {
    const Scene& scene;
    const Overlaps& overlaps;
    const std::vector<bool>& hollow;
    const std::vector<glm::dvec3>& local;       // L_k
    const std::vector<glm::dvec3>& localInner;  // L'_k
    double background = 0.0;
    double radiance = 0.0;  // R
    double maxEta = 0.0;    // the densest medium a ray can be in
    int c = 0;

    const Material& material(std::size_t k) const { return scene.materials[scene.spheres[k].material]; }
    // I_k, for a ray refracted into hollow sphere k, given O_k.
    double into(std::size_t k, double outward) const {
        const Material& m = material(k);
        if (!(m.ks[c] < 1.0)) return radiance;
        return std::min(radiance, (localInner[k][c] + times(m.kt[c], outward)) / (1.0 - m.ks[c]));
    }
    double fromOutside(std::size_t k, double o, double j) const {
        const Material& m = material(k);
        // Total internal reflection entering hollow k needs a denser medium outside.
        const double through = hollow[k] && !(m.eta < maxEta) ? j : std::max(j, o);
        return local[k][c] + times(m.ks[c], o) + times(m.kt[c], through);
    }
    double fromInside(std::size_t k, double o, double j) const {
        const Material& m = material(k);
        return localInner[k][c] + times(m.ks[c], j) + times(m.kt[c], std::max(o, j));
    }
    // F(O, J): each sphere's O and J from the others'.
    void apply(const std::vector<double>& o, const std::vector<double>& j, std::vector<double>& nextO,
               std::vector<double>& nextJ) const {
        const std::size_t n = o.size();
        double best = 0.0, second = 0.0;
        std::size_t bestSphere = n;
        for (std::size_t k = 0; k < n; ++k) {
            const double h = fromOutside(k, o[k], j[k]);
            if (h > best) {
                second = best;
                best = h;
                bestSphere = k;
            } else if (h > second) {
                second = h;
            }
        }
        for (std::size_t i = 0; i < n; ++i) {
            nextO[i] = std::max(background, i == bestSphere ? second : best);
            nextJ[i] = hollow[i] ? 0.0 : fromInside(i, o[i], j[i]);
        }
        for (const auto& [a, b] : overlaps.pairs) {  // a's surface may lie inside b
            nextO[a] = std::max(nextO[a], fromInside(b, o[b], j[b]));
            nextJ[b] = std::max(nextJ[b], std::max(fromOutside(a, o[a], j[a]), fromInside(a, o[a], j[a])));
        }
        for (std::size_t i = 0; i < n; ++i) {
            nextO[i] = std::min(nextO[i], radiance);
            nextJ[i] = hollow[i] ? into(i, nextO[i]) : std::min(nextJ[i], radiance);
        }
    }
    // The least (O, J), checked; false where none is found.
    bool solve(std::vector<double>& o, std::vector<double>& j) const {
        const std::size_t n = scene.spheres.size();
        o.assign(n, 0.0);
        j.assign(n, 0.0);
        std::vector<double> nextO(n), nextJ(n);
        const double work = double(n) + double(overlaps.pairs.size());
        const std::size_t rounds = std::min(std::size_t(kMaxUpdates / work), kMaxRounds);
        if (rounds < kMinRounds) return false;
        auto change = [](double a, double b) { return a == b ? 0.0 : std::abs(a - b) / b; };
        double checked = kInfinity;  // the largest change kCheckRounds ago
        for (std::size_t round = 0; round < rounds; ++round) {
            apply(o, j, nextO, nextJ);
            double largest = 0.0;
            for (std::size_t i = 0; i < n; ++i) largest = std::max({largest, change(o[i], nextO[i]), change(j[i], nextJ[i])});
            o.swap(nextO);
            j.swap(nextJ);
            if (round % kCheckRounds == kCheckRounds - 1) {
                if (!(largest <= 0.5 * checked)) return false;
                checked = largest;
            }
            if (!(largest <= 1e-12)) continue;
            // A vector that F does not raise bounds the least fixed point.
            // (A hollow sphere's J is I of its O, rounded up for the division.)
            for (std::size_t i = 0; i < n; ++i) {
                o[i] *= 1.0 + 1e-8;
                j[i] = hollow[i] ? into(i, o[i]) * (1.0 + 1e-12) : j[i] * (1.0 + 1e-8);
            }
            apply(o, j, nextO, nextJ);
            for (std::size_t i = 0; i < n; ++i)
                if (!(nextO[i] <= o[i] && nextJ[i] <= j[i])) return false;
            return true;
        }
        return false;
    }
};

}  // namespace

ReachBound reachBound(const Scene& scene, const RadianceBound& radiance) {
    const std::size_t n = scene.spheres.size();
    ReachBound b{std::vector<glm::dvec3>(n, radiance.radiance), std::vector<glm::dvec3>(n, radiance.radiance),
                 std::vector<bool>(n, false)};
    const Overlaps o = overlaps(scene);
    if (n == 0 || o.all) return b;
    std::vector<bool> entered(n, false);
    for (const auto& pair : o.pairs) entered[pair.second] = true;
    double maxEta = kAirEta;
    std::vector<glm::dvec3> local(n), localInner(n);
    for (std::size_t i = 0; i < n; ++i) {
        const Sphere& s = scene.spheres[i];
        const Material& m = scene.materials[s.material];
        if (m.refracts()) maxEta = std::max(maxEta, m.eta);
        b.hollow[i] = s.isTrueSphere && m.refracts() && !entered[i];
        local[i] = localInner[i] = scene.ambient * m.kd;
        const Ball ball = boundingBall(s);
        for (const Light& l : scene.lights) {
            local[i] += l.colour * (m.kd + m.ks);
            if (holds(ball, l.position)) localInner[i] += l.colour * (m.kd + m.ks);
        }
    }
    for (int c = 0; c < 3; ++c) {
        const Channel channel{scene, o, b.hollow, local, localInner, scene.background[c], radiance.radiance[c], maxEta, c};
        std::vector<double> outward, inward;
        if (!channel.solve(outward, inward)) continue;
        for (std::size_t i = 0; i < n; ++i) {
            b.outward[i][c] = outward[i];
            b.inward[i][c] = inward[i];
        }
    }
    return b;
}

bool inwardHolds(const Scene& scene, const std::vector<bool>& hollow, const glm::dvec3& eye) {
    for (std::size_t i = 0; i < scene.spheres.size(); ++i)
        if (hollow[i] && holds(boundingBall(scene.spheres[i]), eye)) return false;
    return true;
}

}  // namespace snell
