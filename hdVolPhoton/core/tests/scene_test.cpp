// Scene, lights, cameras and surfaces: sampling consistency of every light, dielectric energy
// conservation, instancing, nested media, the camera inside a closed medium.
#include <gtest/gtest.h>

#include <tuple>

#include "core/diagnostics.h"
#include "core/homogeneousMedium.h"
#include "core/mediumAggregate.h"
#include "core/integratorBase.h"
#include "tests/renderTestUtil.h"
#include "tests/testUtil.h"

using namespace volphoton;
using volphoton::test::meanAndError;

namespace {
MeshDesc sphereMesh(const std::string& name, double radius, int n = 48) {
    MeshDesc m;
    m.name = name;
    for (int i = 0; i <= n; ++i)
        for (int j = 0; j < 2 * n; ++j) {
            double th = Pi * i / n, ph = Pi * j / n;
            m.points.push_back(Vec3(std::sin(th) * std::cos(ph), std::cos(th), std::sin(th) * std::sin(ph)) * radius);
        }
    for (int i = 0; i < n; ++i)
        for (int j = 0; j < 2 * n; ++j) {
            uint32_t a = i * 2 * n + j, b = i * 2 * n + (j + 1) % (2 * n), c = a + 2 * n, d = b + 2 * n;
            m.indices.insert(m.indices.end(), {a, c, b, b, c, d});
        }
    return m;
}

Affine lookAtCamera(const Vec3& eye) {  // looking at the origin along -Z from +Z
    return Affine::translate(eye);
}
}  // namespace

TEST(SceneLights, LightSamplingMatchesHitQueriesForEveryLightWithExtent) {
    // Irradiance-like integral of Le over directions from a point, two ways: by the light's own
    // sampler (Li / pdf) and by uniform sphere directions hitting it (Le / (1/4pi)). Also the pdf
    // returned by intersect() equals the sample's pdf for the same direction.
    Affine rectXf = Affine::translate(Vec3(0, 2, 0));
    rectXf.m[1][1] = 0; rectXf.m[1][2] = 1; rectXf.m[2][1] = -1; rectXf.m[2][2] = 0;  // -Z -> -Y (facing down)
    std::vector<std::pair<std::string, LightPtr>> lights = {
        {"sphere", makeSphereLight(Vec3(0.5, 2, 0.3), 0.4, Spectrum(3.0))},
        {"rect", makeRectLight(rectXf, 1.0, 0.5, Spectrum(2.0))},
        {"disk", makeDiskLight(rectXf, 0.6, Spectrum(2.0))},
        {"distant-cone", makeDistantLight(Vec3(0, -1, 0), 0.2, Spectrum(1.5))},
        {"dome", makeDomeLight(Spectrum(0.7))},
    };
    LatLongImage img;
    img.width = 16;
    img.height = 8;
    for (int y = 0; y < 8; ++y)
        for (int x = 0; x < 16; ++x) img.rgb.insert(img.rgb.end(), {float(1 + x), float(1 + y), float(0.5 + (x * y) % 3)});
    lights.push_back({"dome-texture", makeDomeLight(Spectrum(1.0), img)});
    Vec3 ref(0.1, 0.0, -0.2);
    for (auto& [name, light] : lights) {
        Rng rng(5);
        double viaSample = 0, viaHits = 0, hits2 = 0, sample2 = 0;
        const int n = 400000;
        for (int i = 0; i < n; ++i) {
            LightSample ls = light->sample(ref, rng.uniform(), rng.uniform());
            if (ls.pdf > 0) {
                viaSample += ls.Li[0] / ls.pdf / n;
                sample2 += (ls.Li[0] / ls.pdf) * (ls.Li[0] / ls.pdf) / n;
                double t, pdf;
                Spectrum Le;
                ASSERT_TRUE(light->intersect({ref, ls.wi}, Infinity, &t, &Le, &pdf)) << name;
                EXPECT_NEAR(pdf / ls.pdf, 1.0, 1e-6) << name;
            }
            Vec3 w = uniformSphere(rng.uniform(), rng.uniform());
            double t, pdf;
            Spectrum Le;
            if (light->intersect({ref, w}, Infinity, &t, &Le, &pdf)) {
                viaHits += Le[0] * 4 * Pi / n;
                hits2 += (Le[0] * 4 * Pi) * (Le[0] * 4 * Pi) / n;
            }
        }
        // 4 standard errors of the difference of the two independent estimates.
        double se = std::sqrt((hits2 - viaHits * viaHits) / n + (sample2 - viaSample * viaSample) / n);
        EXPECT_NEAR(viaSample, viaHits, 4 * se) << name;
        EXPECT_LT(se, 0.03 * viaHits) << name;
    }
}

TEST(SceneLights, PhotonEmissionCarriesThePower) {
    // Mean photon flux equals power() for lights whose photons all leave (no scene clipping).
    for (auto light : {makeSphereLight(Vec3(0, 0, 0), 0.0, Spectrum(2.0)), makeSphereLight(Vec3(1, 0, 0), 0.5, Spectrum(1.5)),
                       makeDiskLight(Affine(), 0.5, Spectrum(1.0))}) {
        Rng rng(2);
        double sum = 0;
        const int n = 100000;
        for (int i = 0; i < n; ++i) {
            double u[4] = {rng.uniform(), rng.uniform(), rng.uniform(), rng.uniform()};
            sum += light->emitPhoton(PhotonAim{Vec3(), 10}, u).flux[0] / n;
        }
        EXPECT_NEAR(sum / light->power(10)[0], 1.0, 1e-6) << light->describe();
    }
}

TEST(SceneLights, EmissiveMeshInstancesAreLightsSampledLikeTheirHits) {
    // An emissive 2x2 square at y = 1 facing down (winding), once as authored and once mirrored
    // (scale y -1: at y = -1, and the winding's normal, carried by the inverse transpose, faces up).
    // From ref, each square (distance d = 1) subtends the solid angle
    //   sum over corners (x, y) relative to ref of +-atan(x y / (d sqrt(x^2 + y^2 + d^2)))
    // (the rectangle's solid angle by its corners; 2 pi / 3 on the axis). The mesh light's sampler
    // (1 / pdf) and uniform directions hitting the instance in the BVH (4 pi) both estimate it;
    // pdfAt() at the hit equals the sample's pdf.
    SceneDesc d;
    MeshDesc square;
    square.name = "panel";
    square.points = {Vec3(-1, 1, -1), Vec3(1, 1, -1), Vec3(1, 1, 1), Vec3(-1, 1, 1)};
    square.indices = {0, 1, 2, 0, 2, 3};  // (1,1,-1)-(-1,1,-1) x (1,1,1)-(-1,1,-1) = (2,0,0) x (2,0,2): -Y
    square.material.albedo = Spectrum(0.0);
    square.material.emission = Spectrum(2.0);
    d.meshes.push_back(square);
    d.instances.push_back({0, Affine()});
    d.instances.push_back({0, Affine::scale(Vec3(1, -1, 1))});
    MeshDesc dark = square;  // not emissive: no light
    dark.material.emission = Spectrum(0.0);
    d.meshes.push_back(dark);
    d.instances.push_back({1, Affine::translate(Vec3(0, 0, 5))});
    d.lights.push_back(makeSphereLight(Vec3(5, 0, 0), 0.0, Spectrum(1.0)));
    Scene scene(d);
    ASSERT_EQ(scene.lights().size(), 3u);  // the authored point light, then one per emissive instance
    EXPECT_EQ(scene.instanceLight(2), -1);
    const Vec3 ref(0.1, 0.0, -0.2);
    auto corner = [](double x, double y) { return std::atan(x * y / std::sqrt(x * x + y * y + 1)); };
    const double omega = corner(1 - ref.x, 1 - ref.z) - corner(-1 - ref.x, 1 - ref.z) - corner(1 - ref.x, -1 - ref.z) +
                         corner(-1 - ref.x, -1 - ref.z);
    for (int inst = 0; inst < 2; ++inst) {
        int li = scene.instanceLight(inst);
        ASSERT_GE(li, 1);
        const Light& light = *scene.lights()[li];
        EXPECT_NEAR(light.power(1)[0], 2.0 * Pi * 4, 1e-9);
        Rng rng(11);
        const int n = 200000;
        double viaSample = 0, viaHits = 0, hits2 = 0, sample2 = 0;
        for (int i = 0; i < n; ++i) {
            LightSample ls = light.sample(ref, rng.uniform(), rng.uniform());
            if (ls.pdf > 0) {
                viaSample += 1 / ls.pdf / n;
                sample2 += 1 / (ls.pdf * ls.pdf) / n;
                SurfaceHit hit;
                ASSERT_TRUE(scene.intersect({ref, ls.wi}, 0, Infinity, &hit));
                EXPECT_EQ(hit.instance, inst);
                EXPECT_LT(ls.dist, hit.t);  // the shadow ray stops short of the emitter
                EXPECT_NEAR(light.pdfAt(ref, hit.p, hit.ng) / ls.pdf, 1.0, 1e-4);
                EXPECT_LT(dot(ls.wi, hit.ng), 0);  // the emitting side faces the reference point
            }
            Vec3 w = uniformSphere(rng.uniform(), rng.uniform());
            SurfaceHit hit;
            if (scene.intersect({ref, w}, 0, Infinity, &hit) && hit.instance == inst) {
                viaHits += 4 * Pi / n;
                hits2 += 16 * Pi * Pi / n;
            }
        }
        double se = std::sqrt((hits2 - viaHits * viaHits) / n + (sample2 - viaSample * viaSample) / n);
        EXPECT_NEAR(viaSample, viaHits, 4 * se) << inst;
        EXPECT_NEAR(viaSample, omega, 4 * std::sqrt((sample2 - viaSample * viaSample) / n)) << inst;
        // Photons carry the power and leave from the front side.
        double flux = 0;
        for (int i = 0; i < 20000; ++i) {
            double u[4] = {rng.uniform(), rng.uniform(), rng.uniform(), rng.uniform()};
            PhotonEmission e = light.emitPhoton(PhotonAim{Vec3(), 10}, u);
            flux += e.flux[0] / 20000;
            EXPECT_LT(e.ray.d.y * (inst == 0 ? 1 : -1), 0);
            SurfaceHit self;
            EXPECT_FALSE(scene.intersect(e.ray, 0, Infinity, &self) && self.instance == inst);
        }
        EXPECT_NEAR(flux / light.power(1)[0], 1.0, 1e-9);
    }
    // Off: no mesh lights (hits only).
    d.emissiveMeshLights = false;
    Scene hitsOnly(d);
    EXPECT_EQ(hitsOnly.lights().size(), 1u);
    EXPECT_EQ(hitsOnly.instanceLight(0), -1);
}

TEST(SceneLights, FocusedDistantAndDomePhotonsCarryTheIrradiance) {
    // Photons of a distant light (irradiance E along -Y) and of a constant dome aimed at a scene of
    // radius 10 with a focus sphere of radius 0.5 off centre: the flux through a small square
    // target, inside the focus or outside it, is E x its area (the distant light) or pi L x its area
    // (the dome, for a horizontal target seen from above), within 4 standard errors.
    PhotonAim aim{Vec3(0, 0, 0), 10.0, Vec3(3, 0, 1), 0.5};
    struct Target { Vec3 c; double half; };
    for (Target target : {Target{Vec3(3, 0, 1), 0.2}, Target{Vec3(-6, 0, 2), 0.5}}) {
        double area = 4 * target.half * target.half;
        for (auto [name, light, expected] :
             {std::tuple<const char*, LightPtr, double>{"distant", makeDistantLight(Vec3(0, -1, 0), 0.0, Spectrum(2.0)), 2.0 * area},
              std::tuple<const char*, LightPtr, double>{"dome", makeDomeLight(Spectrum(1.5)), Pi * 1.5 * area}}) {
            Rng rng(7);
            const int n = 400000;
            double sum = 0, sum2 = 0;
            for (int i = 0; i < n; ++i) {
                double u[4] = {rng.uniform(), rng.uniform(), rng.uniform(), rng.uniform()};
                PhotonEmission e = light->emitPhoton(aim, u);
                if (!(e.ray.d.y < 0)) continue;  // only downward photons cross the target from above
                double t = (target.c.y - e.ray.o.y) / e.ray.d.y;
                Vec3 p = e.ray.at(t);
                double f = std::abs(p.x - target.c.x) <= target.half && std::abs(p.z - target.c.z) <= target.half ? e.flux[0] : 0.0;
                sum += f / n;
                sum2 += f * f / n;
            }
            double se = std::sqrt((sum2 - sum * sum) / n);
            EXPECT_NEAR(sum, expected, 4 * se + 1e-12) << name << " at " << target.c.x;
            EXPECT_LT(se, 0.1 * expected) << name << " at " << target.c.x;
        }
    }
}

TEST(SceneLights, SpotFalloff) {
    EXPECT_EQ(spotFalloff(1.0, 0.5, 0.2), 1.0);
    EXPECT_EQ(spotFalloff(std::cos(0.6), 0.5, 0.2), 0.0);
    double mid = spotFalloff(std::cos(0.45), 0.5, 0.2);
    EXPECT_GT(mid, 0.0);
    EXPECT_LT(mid, 1.0);
}

TEST(SceneCamera, PerspectiveOrthographicAndDepthOfField) {
    CameraDesc d;
    d.cameraToWorld = Affine::translate(Vec3(0, 0, 5));
    d.tanHalfFovX = 0.5;
    Camera cam(d, 100, 50);
    double tMin, tMax;
    Ray c = cam.generateRay(50, 25, 0.5, 0.5, &tMin, &tMax);
    EXPECT_NEAR(c.d.z, -1, 1e-12);
    Ray right = cam.generateRay(100, 25, 0.5, 0.5, &tMin, &tMax);
    EXPECT_NEAR(right.d.x / -right.d.z, 0.5, 1e-12);
    Ray top = cam.generateRay(50, 0, 0.5, 0.5, &tMin, &tMax);
    EXPECT_NEAR(top.d.y / -top.d.z, 0.25, 1e-12);  // aspect 2:1
    d.projection = CameraDesc::Projection::Orthographic;
    d.orthoWidth = 4;
    Camera ortho(d, 100, 50);
    Ray o = ortho.generateRay(100, 25, 0.5, 0.5, &tMin, &tMax);
    EXPECT_NEAR(o.o.x, 2, 1e-12);
    EXPECT_NEAR(o.d.z, -1, 1e-12);
    // Thin lens: every lens sample's ray passes through the same point on the focus plane.
    d.projection = CameraDesc::Projection::Perspective;
    d.lensRadius = 0.1;
    d.focusDistance = 3;
    Camera dof(d, 100, 50);
    for (double u : {0.1, 0.5, 0.9}) {
        Ray r = dof.generateRay(70, 20, u, 1 - u, &tMin, &tMax);
        double t = (5 - 3 - r.o.z) / r.d.z;
        Ray ref = dof.generateRay(70, 20, 0, 0, &tMin, &tMax);
        double tr = (5 - 3 - ref.o.z) / ref.d.z;
        EXPECT_NEAR(length(r.at(t) - ref.at(tr)), 0, 1e-9);
    }
    d.cameraToWorld.m[0][0] = 0;  // singular
    EXPECT_THROW(Camera(d, 10, 10), std::invalid_argument);
}

namespace {
/// Mean over a small image, per seed.
test::MeanAndError furnaceMean(const SceneDesc& d, RenderSettings::Integrator integrator, int spp = 16) {
    RenderSettings s = test::smallSettings(integrator, spp, 0);
    s.photonsPerPass = 8000;
    s.initialRadius = 0.1;
    return test::imageMean(d, s, [](const Film& f) { return test::aovMean(f, Film::Beauty, 0); });
}
}  // namespace

TEST(SceneSurfaces, DielectricSpheresDisappearInAFurnace) {
    // Glass (no medium) and a non-absorbing translucent object (albedo-1 medium behind an ior 1.5
    // boundary) in a uniform dome: Fresnel both ways, total internal reflection and the 1/eta^2
    // radiance scaling must cancel, so every pixel equals the dome.
    for (bool withMedium : {false, true}) {
        SceneDesc d;
        d.meshes.push_back(sphereMesh("ball", 1.0));
        d.meshes[0].material.kind = SurfaceMaterial::Kind::Dielectric;
        d.meshes[0].material.ior = 1.5;
        if (withMedium) {
            d.media.push_back(std::make_shared<HomogeneousMedium>(MediumCoefficients::fromAlbedo(3.0, Spectrum(1.0), Spectrum(1.0), Spectrum(0.0), makeHenyeyGreensteinPhase(0.5))));
            d.meshes[0].interiorMedium = 0;
        }
        d.instances.push_back({0, Affine()});
        d.lights.push_back(makeDomeLight(Spectrum(1.0)));
        d.camera.cameraToWorld = lookAtCamera(Vec3(0, 0, 3.5));
        d.camera.tanHalfFovX = 0.3;
        auto pt = furnaceMean(d, RenderSettings::Integrator::PathTracer);
        EXPECT_NEAR(pt.mean, 1.0, 4 * pt.stderr_ + 1e-3) << "path tracer, medium " << withMedium;  // 1e-3: tessellation
        auto pm = furnaceMean(d, RenderSettings::Integrator::PhotonMap, 4);
        EXPECT_NEAR(pm.mean, 1.0, 4 * pm.stderr_ + 0.03) << "photon map, medium " << withMedium;  // + kernel bias at the boundary
    }
}

TEST(SceneSurfaces, LambertianFloorUnderDistantLight) {
    // A large white floor (albedo a) under a delta distant light of irradiance E at normal incidence,
    // seen from above with nothing else: radiance a E / pi everywhere.
    SceneDesc d;
    MeshDesc floor;
    floor.points = {Vec3(-100, 0, -100), Vec3(100, 0, -100), Vec3(100, 0, 100), Vec3(-100, 0, 100)};
    floor.indices = {0, 2, 1, 0, 3, 2};
    floor.material.albedo = Spectrum(0.6);
    d.meshes.push_back(floor);
    d.instances.push_back({0, Affine()});
    d.lights.push_back(makeDistantLight(Vec3(0, -1, 0), 0.0, Spectrum(Pi)));
    Affine down = Affine::translate(Vec3(0, 3, 0));
    down.m[1][1] = 0; down.m[1][2] = 1; down.m[2][1] = -1; down.m[2][2] = 0;  // camera -Z -> world -Y
    d.camera.cameraToWorld = down;
    for (auto integrator : {RenderSettings::Integrator::PathTracer, RenderSettings::Integrator::PhotonMap}) {
        auto m = furnaceMean(d, integrator, 2);
        EXPECT_NEAR(m.mean, 0.6, 1e-6);  // deterministic up to the film's float rounding
    }
}

TEST(SceneInstancing, InstancesShareAMeshAndBadTransformsAreSkipped) {
    SceneDesc d;
    d.meshes.push_back(sphereMesh("ball", 0.5, 8));
    d.instances.push_back({0, Affine::translate(Vec3(-2, 0, 0))});
    d.instances.push_back({0, Affine::translate(Vec3(2, 0, 0))});
    Affine singular = Affine::scale(Vec3(1, 0, 1));
    d.instances.push_back({0, singular});
    Scene scene(d);
    SurfaceHit hit;
    EXPECT_TRUE(scene.intersect({Vec3(-2, 0, 5), Vec3(0, 0, -1)}, 0, Infinity, &hit));
    EXPECT_EQ(hit.instance, 0);
    EXPECT_NEAR(hit.t, 4.5, 1e-3);
    EXPECT_TRUE(scene.intersect({Vec3(2, 0, 5), Vec3(0, 0, -1)}, 0, Infinity, &hit));
    EXPECT_EQ(hit.instance, 1);
    EXPECT_NEAR(std::abs(hit.ng.z), 1.0, 0.05);  // a coarse 8x16 tessellation: facets tilt by up to ~16 degrees
    EXPECT_FALSE(scene.intersect({Vec3(0, 0, 5), Vec3(0, 0, -1)}, 0, Infinity, &hit));  // the singular one is skipped
}

TEST(SceneInstancing, SingleInstanceMeshesAreFlattenedWithTheSameHits) {
    // A mesh with one instance goes into the top-level scene as world-space triangles, a shared mesh
    // stays instanced; either way a hit names its instance and mesh, and its point lies on the
    // world-space plane (rebuilt in double). Mesh 2's first instance is singular (skipped): its one
    // valid instance is flattened.
    MeshDesc quad;
    quad.points = {Vec3(-1, -1, 0), Vec3(1, -1, 0), Vec3(1, 1, 0), Vec3(-1, 1, 0)};
    quad.indices = {0, 1, 2, 0, 2, 3};
    SceneDesc d;
    for (const char* name : {"shared", "single", "afterSingular"}) {
        d.meshes.push_back(quad);
        d.meshes.back().name = name;
    }
    d.instances.push_back({0, Affine::translate(Vec3(-3, 0, 0))});
    d.instances.push_back({0, Affine::translate(Vec3(3, 0, 0))});
    d.instances.push_back({1, Affine::translate(Vec3(0, 0, -2.125)) * Affine::scale(Vec3(2, 2, -2))});  // mirrored
    d.instances.push_back({2, Affine::scale(Vec3(1, 0, 1))});
    d.instances.push_back({2, Affine::translate(Vec3(0, 10, -1))});
    Scene scene(d);
    struct Case {
        Vec3 origin;
        int instance, mesh;
        double z;
    };
    for (const Case& c : {Case{Vec3(-3, 0.3, 5), 0, 0, 0.0}, Case{Vec3(3.2, 0, 5), 1, 0, 0.0}, Case{Vec3(1.5, -1.5, 5), 2, 1, -2.125},
                          Case{Vec3(0.5, 10.5, 5), 4, 2, -1.0}}) {
        SurfaceHit hit;
        ASSERT_TRUE(scene.intersect({c.origin, Vec3(0, 0, -1)}, 0, Infinity, &hit)) << c.instance;
        EXPECT_EQ(hit.instance, c.instance);
        EXPECT_EQ(hit.mesh, c.mesh);
        EXPECT_NEAR(hit.t, 5 - c.z, 1e-5);
        EXPECT_EQ(hit.p.z, c.z) << c.instance;  // exact: the barycentric point of the double-precision plane
        EXPECT_NEAR(std::abs(hit.ng.z), 1.0, 1e-12);
    }
    SurfaceHit hit;
    EXPECT_FALSE(scene.intersect({Vec3(0, 0, 5), Vec3(0, 1, 0)}, 0, Infinity, &hit));
}

TEST(SceneInstancing, NearestSurfaceMatchesTheBoxDistanceForFlatAndInstancedMeshes) {
    // A unit box instanced twice (an Embree instance, one of them stretched: no similarity transform)
    // and once more as its own mesh (flattened into the top-level scene): the nearest surface point of
    // random points inside and outside is the exact distance to the nearest box, in double.
    SceneDesc d;
    d.meshes.push_back(test::boxMesh("shared", Vec3(0, 0, 0), Vec3(1, 1, 1)));
    d.meshes.push_back(test::boxMesh("single", Vec3(0, 0, 0), Vec3(1, 1, 1)));
    const Bounds3 boxes[3] = {{Vec3(-4, 0, 0), Vec3(-3, 1, 1)}, {Vec3(3, 0, 0), Vec3(6, 0.5, 1)}, {Vec3(0, 4, 0), Vec3(1, 5, 1)}};
    d.instances.push_back({0, Affine::translate(boxes[0].lo)});
    d.instances.push_back({0, Affine::translate(boxes[1].lo) * Affine::scale(Vec3(3, 0.5, 1))});
    d.instances.push_back({1, Affine::translate(boxes[2].lo)});
    Scene scene(d);
    auto boxDistance = [](const Bounds3& b, const Vec3& p) {
        if (b.contains(p)) return std::min({p.x - b.lo.x, b.hi.x - p.x, p.y - b.lo.y, b.hi.y - p.y, p.z - b.lo.z, b.hi.z - p.z});
        Vec3 q = vmin(vmax(p, b.lo), b.hi);
        return length(p - q);
    };
    Rng rng(1234);
    int found = 0;
    for (int i = 0; i < 2000; ++i) {
        Vec3 p(-6 + 14 * rng.uniform(), -2 + 9 * rng.uniform(), -2 + 5 * rng.uniform());
        double expected = std::min({boxDistance(boxes[0], p), boxDistance(boxes[1], p), boxDistance(boxes[2], p)});
        const double reach = 1.5;
        std::optional<Scene::NearestSurface> s = scene.nearestSurface(p, reach);
        ASSERT_EQ(s.has_value(), expected < reach) << p.x << " " << p.y << " " << p.z;
        if (!s) continue;
        ++found;
        EXPECT_NEAR(s->distance, expected, 1e-12);
        EXPECT_NEAR(length(p - s->p), expected, 1e-12);
        EXPECT_NEAR(length(s->towards), 1.0, 1e-12);
        if (expected > 1e-9) {
            EXPECT_NEAR(length(s->p + s->towards * s->distance - p), 0.0, 1e-9);
        }
    }
    EXPECT_GT(found, 300);  // both branches are exercised
    EXPECT_FALSE(Scene(SceneDesc()).nearestSurface(Vec3(0, 0, 0), 10));
    EXPECT_FALSE(scene.nearestSurface(Vec3(1e30, 0, 0), Infinity));  // beyond float's range: nothing, no assert
    EXPECT_FALSE(scene.nearestSurface(Vec3(0, std::nan(""), 0), 10));
}

TEST(SceneMedia, NestedMediaAndCameraInsideAClosedMesh) {
    SceneDesc d;
    d.media.push_back(std::make_shared<HomogeneousMedium>(MediumCoefficients::fromAlbedo(0.5, Spectrum(1.0), Spectrum(0.5), Spectrum(0.0), makeIsotropicPhase())));
    d.media.push_back(std::make_shared<HomogeneousMedium>(MediumCoefficients::fromAlbedo(4.0, Spectrum(1.0), Spectrum(0.5), Spectrum(0.0), makeIsotropicPhase())));
    d.meshes.push_back(sphereMesh("outer", 3.0));
    d.meshes.push_back(sphereMesh("inner", 1.0));
    for (int i = 0; i < 2; ++i) {
        d.meshes[i].material.kind = SurfaceMaterial::Kind::Boundary;
        d.meshes[i].interiorMedium = i;
        d.instances.push_back({i, Affine()});
    }
    Scene scene(d);
    MediumStack atCenter = scene.stackAt(Vec3(0.1, 0.05, 0));
    ASSERT_EQ(atCenter.size, 2);
    EXPECT_EQ(atCenter.innermost(), 1);
    EXPECT_EQ(scene.stackAt(Vec3(2, 0, 0)).innermost(), 0);
    EXPECT_EQ(scene.stackAt(Vec3(5, 0, 0)).size, 0);
    // The inner medium replaces the outer one: one member in the aggregate, sigma_t 4.
    MediumAggregate m = scene.mediaFor(atCenter);
    EXPECT_EQ(m.size(), 1);
    EXPECT_DOUBLE_EQ(m.properties(Vec3()).sigma_t()[0], 4.0);
    // Transmittance from the centre to outside: exp(-(4 * 1 + 0.5 * 2)) through both boundaries.
    RenderSettings s;
    auto pt = makePathTracer(scene, s);
    struct Probe : Integrator {
        using Integrator::Integrator;
        PathRadiance Li(const Ray&, double, double, Rng&) const override { return {}; }
        Spectrum T(const Vec3& p, const Vec3& w, double dist, MediumStack st, Rng& rng) const { return shadowTransmittance(p, w, dist, st, rng); }
    } probe(scene, s);
    Rng rng(1);
    Spectrum T = probe.T(Vec3(0, 0, 0), Vec3(1, 0, 0), 10, atCenter, rng);
    EXPECT_NEAR(T[0], std::exp(-5.0), 2e-3);  // tessellated spheres: radii within 0.2%
}

TEST(SceneCamera, FarClipHidesGeometryNotTheEnvironment) {
    // USD cameras always have a finite far clip; rays that pass it without a hit still see the dome.
    SceneDesc d;
    d.meshes.push_back(sphereMesh("ball", 1.0, 16));
    d.instances.push_back({0, Affine::translate(Vec3(0, 0, -20))});
    d.lights.push_back(makeDomeLight(Spectrum(0.5)));
    d.camera.farClip = 10;
    for (auto integrator : {RenderSettings::Integrator::PathTracer, RenderSettings::Integrator::PhotonMap}) {
        RenderSettings s;
        s.integrator = integrator;
        s.width = s.height = 4;
        s.samplesPerPixel = 1;
        Renderer r(std::make_shared<Scene>(d), s);
        r.render();
        for (float v : r.film().resolveRgb(Film::Beauty)) EXPECT_FLOAT_EQ(v, 0.5f);
    }
}

TEST(SceneMedia, OpenMeshMediumIsCutAtItsBoundsNotInfinite) {
    // A fog cube with one face missing: paths leave through the hole. Neither integrator may crash
    // or wander an infinite medium; the medium ends at the mesh's bounding box and the dome shows.
    SceneDesc d;
    MeshDesc cube = test::boxMesh("openCube", Vec3(-1, -1, -1), Vec3(1, 1, 1));
    cube.indices.resize(cube.indices.size() - 6);  // no +x face
    cube.material.kind = SurfaceMaterial::Kind::Boundary;
    cube.interiorMedium = 0;
    d.media.push_back(std::make_shared<HomogeneousMedium>(MediumCoefficients::fromAlbedo(2.0, Spectrum(1.0), Spectrum(0.9), Spectrum(0.0), makeIsotropicPhase())));
    d.meshes.push_back(cube);
    d.instances.push_back({0, Affine()});
    d.lights.push_back(makeDomeLight(Spectrum(1.0)));
    d.camera.cameraToWorld = Affine::translate(Vec3(0.3, 0.2, 5));
    for (auto integrator : {RenderSettings::Integrator::PathTracer, RenderSettings::Integrator::PhotonMap}) {
        RenderSettings s;
        s.integrator = integrator;
        s.width = s.height = 16;
        s.samplesPerPixel = 4;
        s.photonsPerPass = 2000;
        Renderer r(std::make_shared<Scene>(d), s);
        r.render();
        double sum = 0;
        for (float v : r.film().resolveRgb(Film::Beauty)) {
            ASSERT_TRUE(std::isfinite(v));
            sum += v;
        }
        // A non-absorbing-ish fog in a dome: the image is bright, not black from lost paths.
        EXPECT_GT(sum / (16 * 16 * 3), 0.5);
    }
}

TEST(Scene, WarnsWhenMoreMediaOverlapThanAreRendered) {
    using namespace volphoton;
    std::vector<std::string> messages;
    setDiagnosticSink([&](Severity, const std::string& m) { messages.push_back(m); });
    SceneDesc d;
    for (int i = 0; i < MediumAggregate::MaxMedia + 1; ++i) {
        d.media.push_back(std::make_shared<HomogeneousMedium>(
            MediumCoefficients::fromAlbedo(0.1, Spectrum(1.0), Spectrum(0.5), Spectrum(0.0), makeIsotropicPhase())));
        d.unboundedMedia.push_back(i);
    }
    Scene scene(d);
    setDiagnosticSink({});
    bool warned = false;
    for (const std::string& m : messages) warned |= m.find("are ignored") != std::string::npos;
    EXPECT_TRUE(warned);
}

TEST(SceneLights, DielectricsWithNoLightInsideAreSealedFromNextEventEstimation) {
    // Shadow rays stop at dielectric surfaces, so from inside a closed dielectric no light outside
    // it can be sampled: the integrators skip next-event estimation there (Scene::sealedFromLights).
    // A light whose extent overlaps the mesh's bounds, an open mesh or a boundary mesh must not seal.
    auto box = [](const std::string& name, double h) { return test::boxMesh(name, Vec3(-h, -h, -h), Vec3(h, h, h)); };
    auto scene = [&](std::vector<LightPtr> lights, bool emissiveInside) {
        SceneDesc d;
        d.meshes.push_back(box("glass", 1.0));
        d.meshes[0].material.kind = SurfaceMaterial::Kind::Dielectric;
        d.meshes.push_back(box("boundary", 1.0));
        d.meshes[1].material.kind = SurfaceMaterial::Kind::Boundary;
        d.meshes.push_back(box("open", 1.0));
        d.meshes[2].material.kind = SurfaceMaterial::Kind::Dielectric;
        d.meshes[2].indices.resize(d.meshes[2].indices.size() - 6);  // a hole
        d.instances.push_back({0, Affine()});
        d.instances.push_back({1, Affine::translate(Vec3(5, 0, 0))});
        d.instances.push_back({2, Affine::translate(Vec3(-5, 0, 0))});
        if (emissiveInside) {
            d.meshes.push_back(box("ember", 0.1));
            d.meshes[3].material.emission = Spectrum(1.0);
            d.instances.push_back({3, Affine::translate(Vec3(0.2, 0, 0))});
        }
        d.lights = std::move(lights);
        d.camera.cameraToWorld = lookAtCamera(Vec3(0, 0, 10));
        return std::make_unique<Scene>(std::move(d));
    };
    auto sealed = [](const Scene& s, int mesh) {
        MediumStack stack;
        stack.toggle(mesh);
        return s.sealedFromLights(stack);
    };
    std::vector<LightPtr> far = {makeDomeLight(Spectrum(1.0)), makeDistantLight(Vec3(0, -1, 0), 0.0, Spectrum(1.0)),
                                 makeSphereLight(Vec3(0, 3, 0), 0.5, Spectrum(1.0))};
    auto s = scene(far, false);
    EXPECT_TRUE(sealed(*s, 0));
    EXPECT_FALSE(sealed(*s, 1));
    EXPECT_FALSE(sealed(*s, 2));
    EXPECT_FALSE(s->sealedFromLights(MediumStack{}));
    MediumStack nested;  // a boundary nested in the glass: still sealed
    nested.toggle(0);
    nested.toggle(1);
    EXPECT_TRUE(s->sealedFromLights(nested));
    EXPECT_FALSE(sealed(*scene({makeSphereLight(Vec3(0, 1.2, 0), 0.3, Spectrum(1.0))}, false), 0));  // overlaps
    EXPECT_FALSE(sealed(*scene({makeSphereLight(Vec3(0, 0, 0), 0.0, Spectrum(1.0))}, false), 0));    // inside
    EXPECT_FALSE(sealed(*scene(far, true), 0));  // an emissive mesh inside is a light inside
}

namespace {
/// A lambertian floor (albedo 0.5) 40 units wide at y = 0, seen straight down at the origin by a
/// 0.01-unit-wide orthographic camera; no lights.
SceneDesc floorSeenFromAbove() {
    SceneDesc d;
    MeshDesc floor;
    floor.name = "floor";
    floor.points = {Vec3(-20, 0, -20), Vec3(20, 0, -20), Vec3(20, 0, 20), Vec3(-20, 0, 20)};
    floor.indices = {0, 2, 1, 0, 3, 2};
    d.meshes.push_back(floor);
    d.instances.push_back({0, Affine()});
    d.camera = test::lookAt(Vec3(0, 0.5, 0), Vec3(0, 0, 0));
    d.camera.projection = CameraDesc::Projection::Orthographic;
    d.camera.orthoWidth = 0.01;
    return d;
}
}  // namespace

TEST(SceneLights, EveryLightOrOnePickedAtSurfacesGivesTheExactDirectIrradiance) {
    // A lambertian floor (albedo 0.5) under two spherical lights, direct light only: the radiance
    // leaving the floor at the origin is albedo/pi x sum of pi L (r/d)^2 cos(theta) (a sphere wholly
    // above the horizon). Two lights: a lambertian vertex samples both (surfaceSamplesAllLights);
    // with three more lights that send nothing upwards it picks one of five by power. Either way
    // the MIS weights against cosine sampling must sum to one: the path tracer weighs its light
    // hits with the pick probability of the vertex they came from (the power-heuristic pick there:
    // +14.6%).
    for (int extraLights : {0, 3}) {
        SceneDesc d = floorSeenFromAbove();
        // Large lights, so that cosine sampling finds them often and the MIS weights matter.
        d.lights.push_back(makeSphereLight(Vec3(0, 3, 0), 2.0, Spectrum(1.0)));
        d.lights.push_back(makeSphereLight(Vec3(4, 3, 0), 1.5, Spectrum(1.0)));
        for (int i = 0; i < extraLights; ++i) d.lights.push_back(makeDistantLight(Vec3(0, 1, 0), 0.0, Spectrum(0.01)));
        RenderSettings s = test::smallSettings(RenderSettings::Integrator::PathTracer, 64, 0);
        s.width = s.height = 4;
        s.maxDepth = 1;
        double expected = 0.5 * (4.0 / 9.0 + 2.25 / 25.0 * 0.6);
        auto m = test::imageMean(d, s, [](const Film& f) { return test::aovMean(f, Film::Beauty); });
        EXPECT_NEAR(m.mean, expected, 4 * m.stderr_ + 0.003 * expected) << extraLights << " extra lights, +- " << m.stderr_;
        EXPECT_LT(4 * m.stderr_, 0.01 * expected) << extraLights << " extra lights, mean " << m.mean;  // resolves a 1% bias
    }
}

TEST(SceneLights, AConstantDomeIsLeftToTheLambertianBounce) {
    // A lambertian floor (albedo 0.5) under a constant dome of radiance 1: the path tracer's vertex
    // leaves the dome to its cosine-sampled bounce (surfaceLeavesToBounce), whose density is
    // proportional to the dome's unoccluded integrand, so every sample of the open floor is exactly
    // albedo x 1 (sampling the dome's sphere, as before, gave each sample its own value). Next to a
    // black wall of height h at distance a, infinite along z, the floor sees the dome except the
    // wall's cosine-weighted share 1/2 (1 - a / sqrt(a^2 + h^2)) (a wall infinite along z blocks the
    // directions whose angle from the normal, in the plane across the wall, lies in [pi/2 - atan(h/a),
    // pi/2], whose cosine-weighted share is (sin(pi/2) - sin(pi/2 - atan(h/a))) / 2): the mean must
    // match it with every light sampled and with one picked of six by power (the other five send
    // nothing up), each within 4 standard errors.
    auto floorScene = [](bool wall, int extraLights) {
        SceneDesc d = floorSeenFromAbove();
        if (wall) {
            MeshDesc w;
            w.name = "wall";
            w.points = {Vec3(1, 0, -400), Vec3(1, 0, 400), Vec3(1, 1, 400), Vec3(1, 1, -400)};
            w.indices = {0, 1, 2, 0, 2, 3};
            w.material.albedo = Spectrum(0.0);
            d.meshes.push_back(w);
            d.instances.push_back({1, Affine()});
        }
        d.lights.push_back(makeDomeLight(Spectrum(1.0)));
        for (int i = 0; i < extraLights; ++i) d.lights.push_back(makeDistantLight(Vec3(0, 1, 0), 0.0, Spectrum(0.01)));
        return d;
    };
    RenderSettings s = test::smallSettings(RenderSettings::Integrator::PathTracer, 64, 0);
    s.width = s.height = 4;
    auto beauty = [](const Film& f) { return test::aovMean(f, Film::Beauty); };
    auto open = test::imageMean(floorScene(false, 0), s, beauty);
    EXPECT_NEAR(open.mean, 0.5, 1e-9);
    EXPECT_LT(open.stderr_, 1e-9) << "the open floor's samples differ";
    const double expected = 0.5 * (1 - 0.5 * (1 - 1 / std::sqrt(2.0)));
    for (int extraLights : {0, 5}) {
        auto m = test::imageMean(floorScene(true, extraLights), s, beauty);
        EXPECT_NEAR(m.mean, expected, 4 * m.stderr_) << extraLights << " extra lights, +- " << m.stderr_;
        EXPECT_LT(4 * m.stderr_, 0.01 * expected) << extraLights << " extra lights, mean " << m.mean;  // resolves a 1% bias
    }
}

TEST(Camera, ProjectInvertsGenerateRay) {
    // project() gives back the image position a ray was generated through (perspective and
    // orthographic, a non-square image, a scaled and rotated camera), and refuses points behind the
    // camera, outside the image, or seen through a thin lens.
    for (auto projection : {CameraDesc::Projection::Perspective, CameraDesc::Projection::Orthographic}) {
        CameraDesc d = test::lookAt(Vec3(1, 2, 3), Vec3(0.2, -0.1, 0.4), 0.7);
        for (int r = 0; r < 3; ++r) d.cameraToWorld.m[r][0] *= 2;  // a scaled camera frame
        d.projection = projection;
        d.orthoWidth = 3;
        Camera camera(d, 64, 40);
        for (auto [x, y] : {std::pair{0.25, 0.5}, {31.7, 12.2}, {63.9, 39.9}, {10.0, 38.0}}) {
            double tMin, tMax, px = -1, py = -1;
            Ray ray = camera.generateRay(x, y, 0.5, 0.5, &tMin, &tMax);
            ASSERT_TRUE(camera.project(ray.at(4.0), &px, &py)) << x << ", " << y;
            EXPECT_NEAR(px, x, 1e-9);
            EXPECT_NEAR(py, y, 1e-9);
            EXPECT_FALSE(camera.project(ray.at(-4.0), &px, &py)) << "behind the camera";
        }
        double tMin, tMax, px, py;
        Ray outside = camera.generateRay(-3, 20, 0.5, 0.5, &tMin, &tMax);
        EXPECT_FALSE(camera.project(outside.at(4.0), &px, &py));
        d.lensRadius = 0.1;
        EXPECT_FALSE(Camera(d, 64, 40).project(camera.generateRay(5, 5, 0.5, 0.5, &tMin, &tMax).at(4.0), &px, &py));
    }
}
