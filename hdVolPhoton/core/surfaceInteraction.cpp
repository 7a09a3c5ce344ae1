// Surfaces for both integrators: Fresnel reflectance, emission and its light-sampling density,
// next-event estimation at lambertian surfaces,
// sampling a surface's scattering (boundary crossing, lambertian bounce, dielectric reflection or
// refraction) and the camera paths' whole surface vertex (Integrator::cameraSurfaceHit). Declared in
// integratorBase.h.
#include "core/integratorBase.h"

namespace volphoton {

double fresnelDielectric(double cosI, double eta) {
    cosI = std::clamp(cosI, 0.0, 1.0);
    double sin2T = (1 - cosI * cosI) / (eta * eta);
    if (sin2T >= 1) return 1.0;  // total internal reflection
    double cosT = std::sqrt(1 - sin2T);
    double rs = (cosI - eta * cosT) / (cosI + eta * cosT);
    double rp = (eta * cosI - cosT) / (eta * cosI + cosT);
    return 0.5 * (rs * rs + rp * rp);
}

Spectrum Integrator::directAtLambertian(const Ray& ray, const SurfaceHit& hit, const MediumStack& stack, Rng& rng,
                                        bool mis) const {
    const SurfaceMaterial& m = scene_.mesh(hit.mesh).material;
    if (scene_.sealedFromLights(stack)) return {};  // inside a dielectric no shadow ray can leave
    Vec3 n = dot(-ray.d, hit.ns) >= 0 ? hit.ns : -hit.ns;
    auto estimate = [&](const LightSample& ls, double pickProb) -> Spectrum {
        double cosL = dot(ls.wi, n);
        // The light must be on the viewer's side of the geometric surface too (no light leaks through).
        if (!(cosL > 0) || !(ls.pdf > 0) || ls.Li.isBlack() || dot(ls.wi, hit.ng) * dot(-ray.d, hit.ng) <= 0) return {};
        Spectrum T = shadowTransmittance(hit.p, ls.wi, ls.dist, stack, rng, scene_.spawnTMin(hit, ls.wi));
        double lightDensity = pickProb * ls.pdf;
        double w = mis && !ls.isDelta ? powerHeuristic(lightDensity, cosL * InvPi) : 1.0;
        return m.albedo * (cosL * InvPi) * T * ls.Li * (w / lightDensity);
    };
    if (surfaceSamplesAllLights()) {
        Spectrum sum;
        for (size_t i = 0; i < scene_.lights().size(); ++i) {
            const LightPtr& light = scene_.lights()[i];
            if (mis && surfaceLeavesToBounce(static_cast<int>(i))) continue;
            rng.lightPair(static_cast<int>(i));
            auto [u1, u2] = rng.uniform2();
            sum += estimate(light->sample(hit.p, u1, u2), 1.0);
        }
        return sum;
    }
    rng.event(Rng::Event::Light);
    DirectSample ds = sampleDirect(hit.p, rng);
    return ds.light >= 0 && !(mis && surfaceLeavesToBounce(ds.light)) ? estimate(ds.ls, ds.pickProb) : Spectrum();
}

SurfaceScatter Integrator::scatterSurface(const Ray& ray, const SurfaceHit& hit, MediumStack& stack, Rng& rng,
                                          bool radianceMode) const {
    SurfaceScatter s;
    const SurfaceMaterial& m = scene_.mesh(hit.mesh).material;
    Vec3 wo = -ray.d;
    switch (m.kind) {
        case SurfaceMaterial::Kind::Boundary:
            stack.toggle(hit.mesh);
            s.type = SurfaceScatter::Type::Pass;
            s.next = {hit.p, ray.d};
            s.tMin = scene_.spawnTMin(hit, ray.d);
            s.crossed = true;
            return s;
        case SurfaceMaterial::Kind::Lambertian: {
            if (m.albedo.isBlack()) return s;
            Vec3 n = dot(wo, hit.ns) >= 0 ? hit.ns : -hit.ns;
            auto [c1, c2] = rng.uniform2();
            Vec3 w = Frame::fromZ(n).toWorld(cosineHemisphere(c1, c2));
            if (dot(w, hit.ng) * dot(wo, hit.ng) <= 0) return s;  // shading normal sent it below the surface
            s.type = SurfaceScatter::Type::Diffuse;
            s.next = {hit.p, w};
            s.tMin = scene_.spawnTMin(hit, w);
            s.weight = m.albedo;  // f cos / pdf = (albedo/pi) cos / (cos/pi)
            return s;
        }
        case SurfaceMaterial::Kind::Dielectric: {
            bool inside = stack.contains(hit.mesh);
            double eta = inside ? 1.0 / m.ior : m.ior;  // n_t / n_i along the path
            Vec3 n = dot(wo, hit.ng) >= 0 ? hit.ng : -hit.ng;
            double cosI = dot(wo, n);
            double F = fresnelDielectric(cosI, eta);
            if (rng.uniform() < F) {
                Vec3 r = n * (2 * cosI) - wo;
                s.type = SurfaceScatter::Type::Specular;
                s.next = {hit.p, r};
                s.tMin = scene_.spawnTMin(hit, r);
                return s;
            }
            double sin2T = (1 - cosI * cosI) / (eta * eta);
            double cosT = std::sqrt(std::max(0.0, 1 - sin2T));
            Vec3 t = normalize(-wo / eta + n * (cosI / eta - cosT));
            s.type = SurfaceScatter::Type::Specular;
            s.next = {hit.p, t};
            s.tMin = scene_.spawnTMin(hit, t);
            s.crossed = true;
            if (radianceMode) s.weight = Spectrum(1.0 / (eta * eta));
            stack.toggle(hit.mesh);
            return s;
        }
    }
    return s;
}

Spectrum Integrator::surfaceEmission(const Ray& ray, const SurfaceHit& hit) const {
    const SurfaceMaterial& m = scene_.mesh(hit.mesh).material;
    if (m.kind != SurfaceMaterial::Kind::Lambertian || m.emission.isBlack() || !(dot(ray.d, hit.ng) < 0)) return {};
    return m.emission;
}

double Integrator::emitterDensity(const Vec3& from, const SurfaceHit& hit, bool fromSurface) const {
    int light = scene_.instanceLight(hit.instance);
    if (light < 0) return 0.0;
    double pick = fromSurface ? surfaceLightPickProb(light) : mediumLightPickProb(light);
    return pick * scene_.lights()[light]->pdfAt(from, hit.p, hit.ng);
}

SurfaceStep Integrator::cameraSurfaceHit(PathRay& path, const SurfaceHit& hit, MediumStack& stack, Spectrum& beta,
                                         int& depth, int& crossings, Rng& rng, bool mis,
                                         FunctionRef<void(const Spectrum&)> add, SurfaceScatter* scatter) const {
    const Ray& ray = path.ray;
    const SurfaceMaterial& m = scene_.mesh(hit.mesh).material;
    if (m.kind == SurfaceMaterial::Kind::Boundary) {
        if (++crossings > MaxBoundaryCrossings) return SurfaceStep::Stop;
        path.passBoundary(scatterSurface(ray, hit, stack, rng, true), hit.t);
        return SurfaceStep::Crossed;
    }
    if (++depth > settings_.maxDepth) return SurfaceStep::Stop;
    if (m.kind == SurfaceMaterial::Kind::Lambertian && !m.albedo.isBlack())
        add(beta * directAtLambertian(ray, hit, stack, rng, mis));
    rng.event(Rng::Event::Scatter);
    *scatter = scatterSurface(ray, hit, stack, rng, true);
    if (scatter->type == SurfaceScatter::Type::Absorbed) return SurfaceStep::Stop;
    beta *= scatter->weight;
    path.bounce(scatter->next, scatter->tMin);
    return SurfaceStep::Bounced;
}

}  // namespace volphoton
