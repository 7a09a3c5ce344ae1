// Micro-benchmark of the core's free-flight and transmittance routines, per medium type, and of how
// the grid medium's cost grows with grid size and with empty space.
//
//   build/bench_core [--quick]
//
// Prints a Markdown table: ns per free-flight sample (one complete flight to the first real
// collision or the end of the ray) and per transmittance query, for each medium; then the cost of
// rays through a sparse grid as its bounding box grows with the data held fixed (empty space must be
// ~free), and the measured bias of the deterministic transmittance cut-off.
#include <openvdb/openvdb.h>

#include <chrono>
#include <cstdio>
#include <cstring>
#include <functional>

#include "core/embreeRay.h"
#include "core/exponentialMedium.h"
#include "core/freeFlight.h"
#include "core/gridMedium.h"
#include "core/homogeneousMedium.h"
#include "core/integrator.h"
#include "core/lights.h"
#include "core/mediumAggregate.h"
#include "core/proceduralCloud.h"
#include "core/sampling.h"
#include "core/transmittance.h"
#include "core/workCount.h"
#include "tests/renderTestUtil.h"

using namespace volphoton;

namespace {
double nsPer(int n, const std::function<void(int)>& body) {
    auto t0 = std::chrono::steady_clock::now();
    for (int i = 0; i < n; ++i) body(i);
    return std::chrono::duration<double, std::nano>(std::chrono::steady_clock::now() - t0).count() / n;
}

/// Rays from random points on a sphere of radius R around c towards random points near c.
Ray randomRay(Rng& rng, const Vec3& c, double R) {
    Vec3 o = c + uniformSphere(rng.uniform(), rng.uniform()) * R;
    Vec3 target = c + uniformSphere(rng.uniform(), rng.uniform()) * (0.3 * R);
    return {o, normalize(target - o)};
}

volatile double sink;

void benchMedium(const char* name, const Medium& m, const Vec3& c, double R, int n) {
    Rng rng(1);
    std::vector<Ray> rays;
    for (int i = 0; i < 1024; ++i) rays.push_back(randomRay(rng, c, R));
    double flight = nsPer(n, [&](int i) {
        double tHit = -1;
        sampleFreeFlight(m, rays[i & 1023], 2 * R, rng, [&](const MediumEvent& e) {
            if (rng.uniform() * e.sigmaMaj < e.mp.sigma_t().maxValue()) { tHit = e.t; return false; }
            return true;
        });
        sink = tHit;
    });
    TransmittanceSettings closed, ratio, march;
    ratio.mode = TransmittanceMode::RatioTracking;
    march.mode = TransmittanceMode::RayMarching;
    march.marchStep = R / 64;
    double tc = nsPer(n, [&](int i) { sink = transmittance(m, rays[i & 1023], 2 * R, rng, closed)[0]; });
    double tr = nsPer(n, [&](int i) { sink = transmittance(m, rays[i & 1023], 2 * R, rng, ratio)[0]; });
    double tm = nsPer(n / 4, [&](int i) { sink = transmittance(m, rays[i & 1023], 2 * R, rng, march)[0]; });
    std::printf("| %-28s | %12.0f | %14.0f | %14.0f | %14.0f |\n", name, flight, tc, tr, tm);
}

/// Two dense blobs of radius 6 voxels, `separation` voxels apart: the data is fixed, the bounding
/// box (and the empty space inside it) grows with the separation.
std::shared_ptr<GridMedium> twoBlobs(int separation) {
    auto grid = openvdb::FloatGrid::create(0.0f);
    auto acc = grid->getAccessor();
    for (int b = 0; b < 2; ++b)
        for (int x = -6; x <= 6; ++x)
            for (int y = -6; y <= 6; ++y)
                for (int z = -6; z <= 6; ++z)
                    if (x * x + y * y + z * z <= 36) acc.setValue(openvdb::Coord(x + b * separation, y, z), 1.0f);
    GridMediumDesc d;
    d.filePath = "two blobs";
    d.densityScale = 2.0;
    GridMediumGrids g;
    g.density = grid;
    return std::make_shared<GridMedium>(d, g);
}
/// Benchmark scene 1 (tools/bench/scenes.py, homogeneous_cube) built directly: a boundary box
/// [-1, 1]^3 of sigma_t 2, albedo 0.8, HG g 0.5 under a unit dome, camera at (3, 2.2, 4.4) looking
/// at (0, -0.1, 0) with a 40 degree horizontal field of view.
SceneDesc homogeneousCubeScene() {
    SceneDesc d;
    MeshDesc box = test::boxMesh("cube", Vec3(-1, -1, -1), Vec3(1, 1, 1));
    box.material.kind = SurfaceMaterial::Kind::Boundary;
    box.interiorMedium = 0;
    d.media.push_back(std::make_shared<HomogeneousMedium>(
        MediumCoefficients::fromAlbedo(2.0, Spectrum(1.0), Spectrum(0.8), Spectrum(0.0), makeHenyeyGreensteinPhase(0.5))));
    d.meshes.push_back(box);
    d.instances.push_back({0, Affine()});
    d.lights.push_back(makeDomeLight(Spectrum(1.0)));
    d.camera = test::lookAt(Vec3(3, 2.2, 4.4), Vec3(0, -0.1, 0), std::tan(20 * Pi / 180));
    return d;
}

/// rtcIntersect1 alone: the hit distance of `ray` in `scene` (infinite on a miss).
float rawIntersect(RTCScene scene, const Ray& ray) {
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    RTCRayHit rh = embreeRayHit(ray.o, ray.d, 0.0, Infinity);
    rtcIntersect1(scene, &ctx, &rh);
    return rh.ray.tfar;
}

/// The path tracer's cost per sample and per ray on scene 1 against the cost of the rays alone:
/// Scene::intersect (Embree's rtcIntersect1 and our hit set-up) on rays from points inside the cube in
/// random directions, the rays a path tracer's vertices cast there. Single thread.
void pathTracerThroughput(bool quick) {
    auto scene = std::make_shared<Scene>(homogeneousCubeScene());
    RenderSettings s;
    s.width = 160;
    s.height = 120;
    s.samplesPerPixel = quick ? 16 : 64;
    s.noiseTarget = 0;
    s.threads = 1;  // TBB's parallelism capped at 1: the pass runs on this thread, whose counters we read
    Renderer warm(scene, s);
    warm.render();
    Renderer r(scene, s);
    work::Snapshot before = work::snapshot();
    double ns = nsPer(1, [&](int) { r.render(); });
    work::Count w = work::since(before);
    double samples = double(s.width) * s.height * s.samplesPerPixel;

    Rng rng(5);
    std::vector<Ray> rays;
    for (int i = 0; i < 4096; ++i)
        rays.push_back({Vec3(2 * rng.uniform() - 1, 2 * rng.uniform() - 1, 2 * rng.uniform() - 1) * 0.999,
                        uniformSphere(rng.uniform(), rng.uniform())});
    SurfaceHit hit;
    double nsRay = nsPer(quick ? 200000 : 2000000, [&](int i) { sink = scene->intersect(rays[i & 4095], 0.0, Infinity, &hit); });

    // Raw Embree: the same 12 triangles in one flat scene (no instance level), rtcIntersect1 alone.
    RTCDevice device = rtcNewDevice("verbose=0");
    RTCScene flat = rtcNewScene(device);
    rtcSetSceneFlags(flat, RTC_SCENE_FLAG_ROBUST);
    const MeshDesc& box = scene->desc().meshes[0];
    std::vector<float> points;
    for (const Vec3& p : box.points)
        for (int k = 0; k < 3; ++k) points.push_back(static_cast<float>(p[k]));
    RTCGeometry g = embreeTriangles(device, points, box.indices);
    rtcAttachGeometry(flat, g);
    rtcReleaseGeometry(g);
    rtcCommitScene(flat);
    double nsRaw = nsPer(quick ? 200000 : 2000000, [&](int i) { sink = rawIntersect(flat, rays[i & 4095]); });
    // The same flat scene under one identity instance: what Embree's instance level costs.
    RTCScene top = rtcNewScene(device);
    RTCGeometry instance = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_INSTANCE);
    rtcSetGeometryInstancedScene(instance, flat);
    const float identity[12] = {1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0};
    rtcSetGeometryTransform(instance, 0, RTC_FORMAT_FLOAT3X4_COLUMN_MAJOR, identity);
    rtcCommitGeometry(instance);
    rtcAttachGeometry(top, instance);
    rtcReleaseGeometry(instance);
    rtcCommitScene(top);
    double nsInstanced = nsPer(quick ? 200000 : 2000000, [&](int i) { sink = rawIntersect(top, rays[i & 4095]); });
    rtcReleaseScene(top);
    rtcReleaseScene(flat);
    rtcReleaseDevice(device);

    double nsSample = ns / samples, raysPerSample = w.rays / samples;
    std::printf("\n## Path tracer throughput, scene 1 (homogeneous cube), 160x120 x %d spp, one thread\n\n", s.samplesPerPixel);
    std::printf("| ns per sample | rays per sample | medium lookups per sample | ns per ray, rays alone (Scene::intersect) "
                "| ns per ray, raw Embree, one instance | ns per ray, raw Embree, flat | rays' share of the sample | ns per ray, whole path |\n"
                "|---|---|---|---|---|---|---|---|\n");
    std::printf("| %.0f | %.2f | %.2f | %.0f | %.0f | %.0f | %.0f%% | %.0f |\n", nsSample, raysPerSample, w.lookups / work::HomogeneousLookupCost / samples, nsRay,  // scene 1: homogeneous lookups only
                nsInstanced, nsRaw,
                100 * raysPerSample * nsRay / nsSample, nsSample / raysPerSample);
}

}  // namespace

int main(int argc, char** argv) {
    bool quick = argc > 1 && std::strcmp(argv[1], "--quick") == 0;
    int n = quick ? 20000 : 200000;
    auto hg = makeHenyeyGreensteinPhase(0.3);
    HomogeneousMedium homog(MediumCoefficients::fromAlbedo(1.0, Spectrum(1.0), Spectrum(0.8), Spectrum(0.0), hg), Bounds3{Vec3(-1, -1, -1), Vec3(1, 1, 1)});
    HomogeneousMedium chroma(MediumCoefficients::fromAlbedo(1.0, Spectrum(0.5, 1.0, 2.0), Spectrum(0.8), Spectrum(0.0), hg), Bounds3{Vec3(-1, -1, -1), Vec3(1, 1, 1)});
    ExponentialMedium expo(MediumCoefficients::fromAlbedo(1.0, Spectrum(1.0), Spectrum(0.8), Spectrum(0.0), hg), 1.0, 1.0, Vec3(0, -1, 0), Vec3(0, 1, 0));
    std::string path = "/tmp/volphoton_bench_cloud.vdb";
    writeProceduralCloudVdb(path, 64, 2.0 / 64, 1);
    GridMediumDesc gd;
    gd.filePath = path;
    gd.densityScale = 4.0;
    auto cloud = loadGridMedium(gd);
    Bounds3 cb = cloud->bounds();
    MediumAggregate both;
    both.add(&homog);
    both.add(&expo);

    std::printf("## Free flight and transmittance (ns per query, single thread)\n\n");
    std::printf("| medium                       | free flight  | T closed form  | T ratio track  | T ray march    |\n");
    std::printf("|------------------------------|--------------|----------------|----------------|----------------|\n");
    benchMedium("homogeneous box (warm-up)", homog, Vec3(), 2.0, n / 4);
    benchMedium("homogeneous box", homog, Vec3(), 2.0, n);
    benchMedium("homogeneous chromatic", chroma, Vec3(), 2.0, n);
    benchMedium("exponential (unbounded)", expo, Vec3(), 2.0, n);
    benchMedium("vdb cloud 64^3", *cloud, (cb.lo + cb.hi) * 0.5, 2.0, n);
    benchMedium("aggregate homog + exp", both, Vec3(), 2.0, n);
    std::printf("\n(closed form falls back to ratio tracking for the grid)\n");

    std::printf("\n## Grid cost against grid size (the same cloud shape, 2 scene units wide, at finer voxels)\n\n");
    std::printf("| resolution | active voxels | majorant build (ms) | ns per ratio-tracking query |\n|---|---|---|---|\n");
    for (int res : {32, 64, 128, quick ? 128 : 256}) {
        std::string p = "/tmp/volphoton_bench_cloud_" + std::to_string(res) + ".vdb";
        writeProceduralCloudVdb(p, res, 2.0 / res, 1);
        GridMediumDesc d;
        d.filePath = p;
        d.densityScale = 4.0;
        auto g = loadGridMedium(d);
        Bounds3 gb = g->bounds();
        Vec3 gc = (gb.lo + gb.hi) * 0.5;
        Rng rng(4);
        std::vector<Ray> rays;
        for (int i = 0; i < 1024; ++i) rays.push_back(randomRay(rng, gc, 2.0));
        TransmittanceSettings ratio;
        ratio.mode = TransmittanceMode::RatioTracking;
        double ns = nsPer(n / 4, [&](int i) { sink = transmittance(*g, rays[i & 1023], 4.0, rng, ratio)[0]; });
        std::printf("| %d^3 | %zu | %.1f | %.0f |\n", res, g->activeVoxelCount(), g->majorantBuildSeconds() * 1e3, ns);
        if (quick && res == 128) break;
    }

    std::printf("\n## Grid cost against bounding-box size, data fixed (two blobs)\n\n");
    std::printf("| separation (voxels) | box voxels   | ns/ray, rays through the empty middle | ns/ray through a blob |\n");
    std::printf("|---------------------|--------------|---------------------------------------|-----------------------|\n");
    for (int sep : {32, 128, 512, 2048}) {
        auto g = twoBlobs(sep);
        Bounds3 ib = g->indexBounds();
        double boxVoxels = (ib.hi.x - ib.lo.x) * (ib.hi.y - ib.lo.y) * (ib.hi.z - ib.lo.z);
        Rng rng(2);
        TransmittanceSettings ratio;
        ratio.mode = TransmittanceMode::RatioTracking;
        // Rays along z through the middle (between the blobs) and through the first blob.
        double empty = nsPer(n, [&](int) {
            Ray r{Vec3(sep * 0.5 + 3 * (rng.uniform() - 0.5), 3 * (rng.uniform() - 0.5), -100), Vec3(0, 0, 1)};
            sink = transmittance(*g, r, 200, rng, ratio)[0];
        });
        double blob = nsPer(n, [&](int) {
            Ray r{Vec3(3 * (rng.uniform() - 0.5), 3 * (rng.uniform() - 0.5), -100), Vec3(0, 0, 1)};
            sink = transmittance(*g, r, 200, rng, ratio)[0];
        });
        std::printf("| %19d | %12.3g | %37.0f | %21.0f |\n", sep, boxVoxels, empty, blob);
    }

    std::printf("\n## Bias of the deterministic transmittance cut-off (ratio tracking, aggregate)\n\n");
    // A climbing ray, so the aggregate's majorant is loose and ratio tracking gives fractional T.
    const Ray cutRay{Vec3(-1.5, -0.9, 0), normalize(Vec3(1, 0.5, 0))};
    std::printf("| cutoff | mean T (exact %.5f) | bias (+- 1 s.e.)      | ns/query |\n|--------|------|------|------|\n",
                std::exp(-(*both.opticalDepth(cutRay, 0, 3))[0]));
    for (double cutoff : {0.0, 0.01, 0.05, 0.2}) {
        TransmittanceSettings s;
        s.mode = TransmittanceMode::RatioTracking;
        s.cutoff = cutoff;
        Rng rng(3);
        double exact = std::exp(-(*both.opticalDepth(cutRay, 0, 3))[0]);
        double sum = 0, sum2 = 0;
        int m = n * 5;
        double ns = nsPer(m, [&](int) {
            double T = transmittance(both, cutRay, 3, rng, s)[0];
            sum += T;
            sum2 += T * T;
        });
        double mean = sum / m, se = std::sqrt(std::max(0.0, sum2 / m - mean * mean) / m);
        std::printf("| %6.2f | %.5f | %+.5f +- %.5f | %.0f |\n", cutoff, mean, mean - exact, se, ns);
    }
    pathTracerThroughput(quick);
    return 0;
}
