#include "core/lights.h"

#include <ImfArray.h>
#include <ImfRgbaFile.h>

#include <algorithm>
#include <sstream>
#include <stdexcept>

#include "core/diagnostics.h"
#include "core/sampling.h"
#include "core/scene.h"

namespace volphoton {

double spotFalloff(double cosAngle, double coneAngle, double coneSoftness) {
    double angle = std::acos(std::clamp(cosAngle, -1.0, 1.0));
    if (coneAngle >= Pi) return 1.0;
    double inner = coneAngle * (1 - std::clamp(coneSoftness, 0.0, 1.0));
    if (angle <= inner) return 1.0;
    if (angle >= coneAngle) return 0.0;
    double x = (coneAngle - angle) / (coneAngle - inner);
    return x * x * (3 - 2 * x);
}

bool coneInterval(const Ray& ray, const Vec3& apex, const Vec3& axis, double halfAngle, double* t0, double* t1) {
    *t0 = -Infinity;
    *t1 = Infinity;
    Vec3 o = ray.o - apex;
    double c2 = std::cos(halfAngle) * std::cos(halfAngle);
    double ad = dot(axis, ray.d), ao = dot(axis, o);
    // (a.x)^2 - cos^2 |x|^2 >= 0 on x = o + t d: A t^2 + B t + C >= 0 (both nappes), then a.x >= 0.
    double A = ad * ad - c2, B = 2 * (ad * ao - c2 * dot(ray.d, o)), C = ao * ao - c2 * lengthSquared(o);
    double disc = B * B - 4 * A * C;
    if (std::abs(A) < 1e-9) return true;  // (nearly) along the cone's surface: keep the whole line
    // No real root: with A < 0 the line misses both nappes (at most grazes them); A > 0 cannot miss
    // (rounding): keep the whole line.
    if (disc < 0) return A > 0;
    double q = std::sqrt(disc);
    double r1 = (-B - q) / (2 * A), r2 = (-B + q) / (2 * A);
    if (r1 > r2) std::swap(r1, r2);
    if (A < 0) {  // inside between the roots, on one nappe
        if (ao + 0.5 * (r1 + r2) * ad < 0) return false;
        *t0 = r1;
        *t1 = r2;
    } else if (ad > 0) {  // the positive nappe is where the line goes forward
        *t0 = r2;
    } else {
        *t1 = r1;
    }
    return true;
}

namespace {

void requireFinite(const Spectrum& s, const char* what) {
    if (!s.isFinite() || s.minValue() < 0) throw std::invalid_argument(std::string(what) + ": emission must be finite and >= 0");
}

/// A photon origin upstream of aim's disks for direction `dir` (PhotonAim), and the density of that
/// origin over the plane perpendicular to dir (per unit area).
std::pair<Vec3, double> upstreamPoint(const PhotonAim& aim, const Vec3& dir, double u1, double u2) {
    Frame f = Frame::fromZ(dir);
    // Disk centres in the plane's coordinates, relative to the scene's.
    double fx = dot(aim.focusCenter - aim.center, f.s), fy = dot(aim.focusCenter - aim.center, f.t);
    bool focus = aim.focusRadius > 0;
    double cx = 0, cy = 0, r = aim.radius;
    if (focus && u1 < 0.5) {
        u1 *= 2;
        cx = fx, cy = fy, r = aim.focusRadius;
    } else if (focus) {
        u1 = 2 * u1 - 1;
    }
    double x, y;
    concentricDisk(std::min(u1, std::nextafter(1.0, 0.0)), u2, &x, &y);
    x = cx + x * r, y = cy + y * r;
    double pdf = 1 / (Pi * aim.radius * aim.radius) * (x * x + y * y <= aim.radius * aim.radius ? 1.0 : 0.0);
    if (focus) {
        double dx = x - fx, dy = y - fy;
        pdf = 0.5 * pdf + 0.5 / (Pi * aim.focusRadius * aim.focusRadius) *
                              (dx * dx + dy * dy <= aim.focusRadius * aim.focusRadius ? 1.0 : 0.0);
    }
    Vec3 o = aim.center - dir * aim.radius + f.s * x + f.t * y;
    double t0, t1;
    if (!aim.box.empty() && aim.box.intersect({o, dir}, 0.0, Infinity, &t0, &t1)) {
        // Back from the box's face by 1e-4 of its diagonal (and by far more than the float error of
        // the entry point), so that a surface lying in that face is still met in front of the photon.
        double margin = std::max(1e-4 * length(aim.box.hi - aim.box.lo), 64 * Scene::floatError(o + dir * t0));
        o = o + dir * std::max(0.0, t0 - margin);
    }
    return {o, pdf};
}

class DistantLight final : public Light {
public:
    std::optional<Bounds3> extent() const override { return std::nullopt; }
    DistantLight(const Vec3& dir, double halfAngle, const Spectrum& E) : dir_(normalize(dir)), E_(E) {
        requireFinite(E, "distant light");
        if (!isFinite(dir) || length(dir) == 0) throw std::invalid_argument("distant light: direction must be non-zero");
        halfAngle = std::clamp(halfAngle, 0.0, Pi / 2);
        cosMax_ = std::cos(halfAngle);
        // Uniform cone of radiance L at normal incidence gives E = L pi sin^2(halfAngle).
        double sin2 = 1 - cosMax_ * cosMax_;
        delta_ = sin2 < 1e-12;
        L_ = delta_ ? E : E / (Pi * sin2);
    }
    LightSample sample(const Vec3&, double u1, double u2) const override {
        LightSample s;
        if (delta_) {
            s.wi = -dir_;
            s.Li = E_;
            s.pdf = 1;
            s.isDelta = true;
        } else {
            s.wi = Frame::fromZ(-dir_).toWorld(uniformCone(u1, u2, cosMax_));
            s.Li = L_;
            s.pdf = uniformConePdf(cosMax_);
        }
        return s;
    }
    bool intersect(const Ray& ray, double tMax, double* t, Spectrum* Le, double* pdf) const override {
        if (delta_ || !std::isinf(tMax) || dot(ray.d, -dir_) < cosMax_) return false;
        *t = Infinity;
        *Le = L_;
        *pdf = uniformConePdf(cosMax_);
        return true;
    }
    bool isDelta() const override { return delta_; }
    Spectrum power(double r) const override { return E_ * (Pi * r * r); }
    PhotonEmission emitPhoton(const PhotonAim& aim, double u[4]) const override {
        Vec3 d = delta_ ? dir_ : Frame::fromZ(dir_).toWorld(uniformCone(u[2], u[3], cosMax_));
        auto [o, pdf] = upstreamPoint(aim, d, u[0], u[1]);
        return {{o, d}, pdf > 0 ? E_ / pdf : Spectrum(0.0)};
    }
    std::string describe() const override { return "distant"; }

private:
    Vec3 dir_;
    Spectrum E_, L_;
    double cosMax_;
    bool delta_;
};

class SphereLight final : public Light {
public:
    std::optional<Bounds3> extent() const override {
        Bounds3 b;
        b.extend(p_ - Vec3(r_, r_, r_));
        b.extend(p_ + Vec3(r_, r_, r_));
        return b;
    }
    SphereLight(const Vec3& p, double radius, const Spectrum& L, const Vec3& axis, double coneAngle, double softness)
        : p_(p), r_(std::max(0.0, radius)), L_(L), axis_(axis), cone_(coneAngle), softness_(softness) {
        requireFinite(L, "sphere light");
        if (!isFinite(p) || !std::isfinite(radius)) throw std::invalid_argument("sphere light: position and radius must be finite");
        shaped_ = coneAngle < Pi;
        if (shaped_) axis_ = normalize(axis);
    }
    double shaping(const Vec3& emitDir) const { return shaped_ ? spotFalloff(dot(emitDir, axis_), cone_, softness_) : 1.0; }
    LightSample sample(const Vec3& ref, double u1, double u2) const override {
        LightSample s;
        Vec3 toCenter = p_ - ref;
        double d2 = lengthSquared(toCenter), d = std::sqrt(d2);
        if (d == 0) return s;
        if (r_ == 0 || d <= r_) {  // point light (or reference inside the sphere: treat as a point)
            s.wi = toCenter / d;
            s.dist = d;
            s.Li = L_ * (shaping(-s.wi) / d2);
            if (r_ > 0) s.Li *= Pi * r_ * r_;  // radiance L of a sphere seen from far: I = L pi r^2
            s.pdf = 1;
            s.isDelta = true;
            return s;
        }
        // Uniform sampling of the cone the sphere subtends (pbrt-v4 Sphere::Sample(ctx)).
        double sinMax2 = r_ * r_ / d2, cosMax = std::sqrt(std::max(0.0, 1 - sinMax2));
        Vec3 w = Frame::fromZ(toCenter / d).toWorld(uniformCone(u1, u2, cosMax));
        double tHit;
        if (!hitSphere({ref, w}, &tHit)) tHit = std::sqrt(std::max(0.0, d2 - r_ * r_));
        s.wi = w;
        s.dist = tHit;
        s.Li = L_ * shaping(-w);
        s.pdf = uniformConePdf(cosMax);
        return s;
    }
    bool hitSphere(const Ray& ray, double* t) const {
        Vec3 oc = ray.o - p_;
        double b = dot(oc, ray.d), c = lengthSquared(oc) - r_ * r_;
        double disc = b * b - c;
        if (disc < 0) return false;
        double sq = std::sqrt(disc);
        double t0 = -b - sq, t1 = -b + sq;
        *t = t0 > 1e-9 * (1 + std::abs(b)) ? t0 : t1;
        return *t > 0;
    }
    bool intersect(const Ray& ray, double tMax, double* t, Spectrum* Le, double* pdf) const override {
        if (r_ == 0 || !hitSphere(ray, t) || *t >= tMax) return false;
        double d2 = lengthSquared(p_ - ray.o);
        if (d2 <= r_ * r_) return false;
        double cosMax = std::sqrt(std::max(0.0, 1 - r_ * r_ / d2));
        *Le = L_ * shaping(ray.d);
        *pdf = uniformConePdf(cosMax);
        return true;
    }
    bool isDelta() const override { return r_ == 0; }
    std::optional<Vec3> pointPosition() const override { return r_ == 0 ? std::optional<Vec3>(p_) : std::nullopt; }
    std::optional<Vec3> equiangularCenter() const override { return p_; }
    void litInterval(const Ray& ray, double* t0, double* t1) const override {
        *t0 = -Infinity;
        *t1 = Infinity;
        // A cone narrower than a hemisphere; its apex moved back along the axis by r / sin(angle)
        // contains the sphere, hence every emission direction from any point of it (widened by a
        // hair against rounding: the interval must not cut light off).
        double angle = std::min(cone_ * (1 + 1e-6) + 1e-9, 0.5 * Pi * (1 - 1e-6));
        if (!shaped_ || cone_ >= 0.5 * Pi * (1 - 1e-6)) return;
        Vec3 apex = p_ - axis_ * (r_ * (1 + 1e-6) / std::sin(angle) + 1e-9 * (1 + length(p_)));
        if (!coneInterval(ray, apex, axis_, angle, t0, t1)) *t0 = *t1 = Infinity;  // empty
    }
    Spectrum power(double) const override {
        // Point: 4 pi I; sphere: pi L * 4 pi r^2. Spot shaping scales by the cone's solid-angle share,
        // approximated by its hard cone (used for light selection and photon budgets only).
        double share = shaped_ ? (1 - std::cos(cone_)) / 2 : 1.0;
        return (r_ == 0 ? L_ * (4 * Pi) : L_ * (Pi * 4 * Pi * r_ * r_)) * share;
    }
    PhotonEmission emitPhoton(const PhotonAim&, double u[4]) const override {
        PhotonEmission e;
        if (r_ == 0) {
            Vec3 d = uniformSphere(u[0], u[1]);
            e.ray = {p_, d};
            e.flux = L_ * (shaping(d) / UniformSpherePdf);
        } else {
            Vec3 n = uniformSphere(u[0], u[1]);
            Vec3 d = Frame::fromZ(n).toWorld(cosineHemisphere(u[2], u[3]));
            e.ray = {p_ + n * (r_ * (1 + 1e-9)), d};
            e.flux = L_ * (shaping(d) * Pi * 4 * Pi * r_ * r_);
        }
        return e;
    }
    std::string describe() const override { return r_ == 0 ? "point" : "sphere"; }

private:
    Vec3 p_;
    double r_;
    Spectrum L_;
    Vec3 axis_;
    double cone_, softness_;
    bool shaped_ = false;
};

/// Rect and disk: planar one-sided emitters facing local -Z.
class PlanarLight final : public Light {
public:
    std::optional<Bounds3> extent() const override {
        Bounds3 b;  // the disk's bounding parallelogram, the rect's corners
        for (double x : {-1.0, 1.0})
            for (double y : {-1.0, 1.0}) b.extend(center_ + ex_ * x + ey_ * y);
        return b;
    }
    PlanarLight(const Affine& toWorld, bool disk, double sx, double sy, const Spectrum& L) : disk_(disk), L_(L) {
        requireFinite(L, disk ? "disk light" : "rect light");
        if (!(sx > 0) || !(sy > 0)) throw std::invalid_argument(std::string(disk ? "disk" : "rect") + " light: size must be positive");
        center_ = toWorld.point(Vec3());
        ex_ = toWorld.vector(Vec3(disk ? sx : sx / 2, 0, 0));
        ey_ = toWorld.vector(Vec3(0, disk ? sx : sy / 2, 0));
        Vec3 c = cross(ex_, ey_);
        area_ = length(c) * (disk ? Pi : 4.0);
        if (!(area_ > 0) || !std::isfinite(area_)) throw std::invalid_argument("planar light: degenerate transform");
        // UsdLux: rect and disk lights emit along local -Z; the geometric normal keeps that side under
        // shear and non-uniform scale.
        Vec3 geometric = normalize(cross(ey_, ex_));
        n_ = dot(geometric, toWorld.vector(Vec3(0, 0, -1))) >= 0 ? geometric : -geometric;
    }
    Vec3 pointAt(double u1, double u2) const {
        if (disk_) {
            double x, y;
            concentricDisk(u1, u2, &x, &y);
            return center_ + ex_ * x + ey_ * y;
        }
        return center_ + ex_ * (2 * u1 - 1) + ey_ * (2 * u2 - 1);
    }
    LightSample sample(const Vec3& ref, double u1, double u2) const override {
        LightSample s;
        Vec3 p = pointAt(u1, u2), d = p - ref;
        double dist2 = lengthSquared(d), dist = std::sqrt(dist2);
        if (dist == 0) return s;
        s.wi = d / dist;
        double cosL = -dot(s.wi, n_);
        if (cosL <= 0) return s;
        s.dist = dist;
        s.Li = L_;
        s.pdf = dist2 / (cosL * area_);
        return s;
    }
    bool intersect(const Ray& ray, double tMax, double* t, Spectrum* Le, double* pdf) const override {
        double denom = dot(ray.d, n_);
        if (denom >= 0) return false;  // back side or parallel
        double th = dot(center_ - ray.o, n_) / denom;
        if (!(th > 0) || th >= tMax) return false;
        Vec3 q = ray.at(th) - center_;
        // Coordinates in the (ex, ey) frame; ex and ey may be non-orthogonal under shear.
        double exx = dot(ex_, ex_), eyy = dot(ey_, ey_), exy = dot(ex_, ey_);
        double qx = dot(q, ex_), qy = dot(q, ey_), det = exx * eyy - exy * exy;
        double a = (qx * eyy - qy * exy) / det, b = (qy * exx - qx * exy) / det;
        if (disk_ ? a * a + b * b > 1 : (std::abs(a) > 1 || std::abs(b) > 1)) return false;
        *t = th;
        *Le = L_;
        *pdf = th * th / (-denom * area_);
        return true;
    }
    bool isDelta() const override { return false; }
    Spectrum power(double) const override { return L_ * (Pi * area_); }
    PhotonEmission emitPhoton(const PhotonAim&, double u[4]) const override {
        Vec3 d = Frame::fromZ(n_).toWorld(cosineHemisphere(u[2], u[3]));
        return {{pointAt(u[0], u[1]) + n_ * 1e-9 * (1 + length(center_)), d}, L_ * (Pi * area_)};
    }
    std::string describe() const override { return disk_ ? "disk" : "rect"; }

private:
    bool disk_;
    Spectrum L_;
    Vec3 center_, ex_, ey_, n_;
    double area_;
};

class MeshLight final : public Light {
public:
    std::optional<Bounds3> extent() const override {
        Bounds3 b;
        for (const Vec3& p : points_) b.extend(p);
        return b;
    }
    MeshLight(std::string name, std::vector<Vec3> points, const std::vector<uint32_t>& indices, const Spectrum& L)
        : name_(std::move(name)), points_(std::move(points)), L_(L) {
        requireFinite(L, "mesh light");
        std::vector<double> areas;
        for (size_t t = 0; t + 2 < indices.size(); t += 3) {
            const Vec3 &a = points_[indices[t]], &b = points_[indices[t + 1]], &c = points_[indices[t + 2]];
            Vec3 n = cross(b - a, c - a);
            double area = 0.5 * length(n);
            if (!(area > 0) || !std::isfinite(area)) continue;
            triangles_.push_back({indices[t], indices[t + 1], indices[t + 2], n / (2 * area)});
            areas.push_back(area);
            area_ += area;
        }
        if (!triangles_.empty()) triangleDist_ = Distribution1D(areas);
    }
    bool empty() const { return triangles_.empty(); }

    /// A point uniform over the area and its triangle's unit normal; u1 picks the triangle and is
    /// reused (rescaled) inside it.
    std::pair<Vec3, Vec3> pointAt(double u1, double u2) const {
        double pdf;
        size_t i;
        double x = triangleDist_.sample(u1, &pdf, &i);
        double v = std::clamp(x * triangles_.size() - static_cast<double>(i), 0.0, 1.0);
        const Triangle& tri = triangles_[i];
        double su = std::sqrt(v), b0 = 1 - su, b1 = u2 * su;  // uniform barycentrics (pbrt's)
        return {points_[tri.a] * b0 + points_[tri.b] * b1 + points_[tri.c] * (1 - b0 - b1), tri.n};
    }
    LightSample sample(const Vec3& ref, double u1, double u2) const override {
        LightSample s;
        auto [p, n] = pointAt(u1, u2);
        Vec3 d = p - ref;
        double dist2 = lengthSquared(d), dist = std::sqrt(dist2);
        if (!(dist > 0)) return s;
        s.wi = d / dist;
        double cosL = -dot(s.wi, n);
        if (!(cosL > 0)) return s;
        // Short of the emitter by its float precision along the ray, so that the shadow ray does not
        // meet the emitting triangle itself (shadowTransmittance stops short by the unslanted bound).
        s.dist = std::max(0.0, dist - Scene::floatError(p) / std::max(cosL, Scene::MinSpawnCos));
        s.Li = L_;
        s.pdf = dist2 / (cosL * area_);
        return s;
    }
    bool intersect(const Ray&, double, double*, Spectrum*, double*) const override { return false; }
    bool isGeometry() const override { return true; }
    double pdfAt(const Vec3& ref, const Vec3& p, const Vec3& n) const override {
        Vec3 d = p - ref;
        double dist2 = lengthSquared(d);
        double cosL = -dot(d, n) / std::sqrt(dist2);
        return cosL > 0 && dist2 > 0 ? dist2 / (cosL * area_) : 0.0;
    }
    bool isDelta() const override { return false; }
    Spectrum power(double) const override { return L_ * (Pi * area_); }
    PhotonEmission emitPhoton(const PhotonAim&, double u[4]) const override {
        auto [p, n] = pointAt(u[0], u[1]);
        Vec3 d = Frame::fromZ(n).toWorld(cosineHemisphere(u[2], u[3]));
        // Off the surface by its float precision, so that the photon's first ray does not meet it.
        return {{p + n * (4 * Scene::floatError(p)), d}, L_ * (Pi * area_)};
    }
    std::string describe() const override {
        std::ostringstream o;
        o << "mesh light '" << name_ << "' (" << triangles_.size() << " triangles, area " << area_ << ")";
        return o.str();
    }

private:
    struct Triangle {
        uint32_t a, b, c;
        Vec3 n;  ///< unit geometric normal, (b - a) x (c - a)
    };
    std::string name_;
    std::vector<Vec3> points_;
    std::vector<Triangle> triangles_;
    Distribution1D triangleDist_;
    Spectrum L_;
    double area_ = 0;
};

class DomeLight final : public Light {
public:
    std::optional<Bounds3> extent() const override { return std::nullopt; }
    DomeLight(const Spectrum& L, LatLongImage img, const Affine& toWorld) : L_(L), img_(std::move(img)), toWorld_(toWorld) {
        requireFinite(L, "dome light");
        auto inv = toWorld.inverse();
        if (!inv) throw std::invalid_argument("dome light: transform is not invertible");
        toLight_ = *inv;
        if (img_.width > 0) {
            // Importance ~ luminance * sin(theta) (the lat-long map's solid-angle Jacobian).
            std::vector<double> f(static_cast<size_t>(img_.width) * img_.height);
            for (int y = 0; y < img_.height; ++y) {
                double sinTheta = std::sin(Pi * (y + 0.5) / img_.height);
                for (int x = 0; x < img_.width; ++x) f[y * img_.width + x] = luminance(texel(x, y)) * sinTheta + 1e-12;
            }
            dist_ = Distribution2D(f, img_.width, img_.height);
            for (int y = 0; y < img_.height; ++y)
                for (int x = 0; x < img_.width; ++x) {
                    Spectrum t = texel(x, y);
                    if (!t.isFinite() || t.minValue() < 0) throw std::invalid_argument("dome light: texture has NaN, Inf or negative texels");
                    double sinTheta = std::sin(Pi * (y + 0.5) / img_.height);
                    integral_ += t * (sinTheta * (2 * Pi / img_.width) * (Pi / img_.height));
                }
        } else {
            integral_ = Spectrum(4 * Pi);
        }
    }
    Spectrum texel(int x, int y) const {
        size_t i = 3 * (static_cast<size_t>(y) * img_.width + x);
        return {img_.rgb[i], img_.rgb[i + 1], img_.rgb[i + 2]};
    }
    // Lat-long convention: light-space +Y up; u = 0.5 + atan2(x, -z)/(2 pi), v = acos(y)/pi.
    Spectrum radiance(const Vec3& worldDir, double* pdf) const {
        if (img_.width == 0) {
            *pdf = UniformSpherePdf;
            return L_;
        }
        Vec3 d = normalize(toLight_.vector(worldDir));
        double u = 0.5 + std::atan2(d.x, -d.z) / (2 * Pi), v = std::acos(std::clamp(d.y, -1.0, 1.0)) / Pi;
        int x = std::clamp(static_cast<int>(u * img_.width), 0, img_.width - 1);
        int y = std::clamp(static_cast<int>(v * img_.height), 0, img_.height - 1);
        double sinTheta = std::sqrt(std::max(0.0, 1 - d.y * d.y));
        *pdf = sinTheta > 0 ? dist_.pdf(u, v) / (2 * Pi * Pi * sinTheta) : 0.0;
        return L_ * texel(x, y);
    }
    Vec3 sampleDirection(double u1, double u2, double* pdf) const {
        if (img_.width == 0) {
            *pdf = UniformSpherePdf;
            return uniformSphere(u1, u2);
        }
        double u, v, mapPdf;
        dist_.sample(u1, u2, &u, &v, &mapPdf);
        double theta = v * Pi, phi = (u - 0.5) * 2 * Pi;
        double sinTheta = std::sin(theta);
        Vec3 d(sinTheta * std::sin(phi), std::cos(theta), -sinTheta * std::cos(phi));
        *pdf = sinTheta > 0 ? mapPdf / (2 * Pi * Pi * sinTheta) : 0.0;
        return normalize(toWorld_.vector(d));
    }
    bool isConstantDome() const override { return img_.width == 0; }
    LightSample sample(const Vec3&, double u1, double u2) const override {
        LightSample s;
        s.wi = sampleDirection(u1, u2, &s.pdf);
        double pdf;
        s.Li = radiance(s.wi, &pdf);
        return s;
    }
    bool intersect(const Ray& ray, double tMax, double* t, Spectrum* Le, double* pdf) const override {
        if (!std::isinf(tMax)) return false;
        *t = Infinity;
        *Le = radiance(ray.d, pdf);
        return true;
    }
    bool isDelta() const override { return false; }
    bool isDome() const override { return true; }
    Spectrum power(double r) const override { return L_ * integral_ * (Pi * r * r); }
    PhotonEmission emitPhoton(const PhotonAim& aim, double u[4]) const override {
        double pdf;
        Vec3 toLight = sampleDirection(u[2], u[3], &pdf);
        double pdfDummy;
        Spectrum L = radiance(toLight, &pdfDummy);
        Vec3 d = -toLight;
        auto [o, areaPdf] = upstreamPoint(aim, d, u[0], u[1]);
        return {{o, d}, pdf > 0 && areaPdf > 0 ? L / (pdf * areaPdf) : Spectrum(0.0)};
    }
    std::string describe() const override { return img_.width ? "dome(texture)" : "dome"; }

private:
    Spectrum L_;
    LatLongImage img_;
    Affine toWorld_, toLight_;
    Distribution2D dist_;
    Spectrum integral_;
};

}  // namespace

LatLongImage loadLatLongExr(const std::string& path) {
    try {
        Imf::RgbaInputFile file(path.c_str());
        Imath::Box2i dw = file.dataWindow();
        int w = dw.max.x - dw.min.x + 1, h = dw.max.y - dw.min.y + 1;
        if (w <= 0 || h <= 0 || static_cast<long>(w) * h > (1L << 28)) throw std::runtime_error("bad image size");
        Imf::Array2D<Imf::Rgba> px(h, w);
        file.setFrameBuffer(&px[0][0] - dw.min.x - dw.min.y * w, 1, w);
        file.readPixels(dw.min.y, dw.max.y);
        LatLongImage img;
        img.width = w;
        img.height = h;
        img.rgb.resize(static_cast<size_t>(w) * h * 3);
        size_t bad = 0;
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                float c[3] = {px[y][x].r, px[y][x].g, px[y][x].b};
                for (int k = 0; k < 3; ++k) {
                    if (!std::isfinite(c[k]) || c[k] < 0) { c[k] = 0; ++bad; }
                    img.rgb[3 * (static_cast<size_t>(y) * w + x) + k] = c[k];
                }
            }
        if (bad) {
            std::ostringstream msg;
            msg << "dome texture '" << path << "': " << bad << " NaN, Inf or negative values clamped to 0";
            warn(msg.str());
        }
        return img;
    } catch (const std::exception& e) {
        throw std::runtime_error("cannot read environment texture '" + path + "': " + e.what());
    }
}

LightPtr makeDistantLight(const Vec3& direction, double halfAngle, const Spectrum& E) {
    return std::make_shared<DistantLight>(direction, halfAngle, E);
}
LightPtr makeSphereLight(const Vec3& p, double radius, const Spectrum& L) {
    return std::make_shared<SphereLight>(p, radius, L, Vec3(0, 0, -1), Pi, 0.0);
}
LightPtr makeSpotLight(const Vec3& p, double radius, const Spectrum& L, const Vec3& axis, double coneAngle, double softness) {
    if (!(coneAngle > 0)) throw std::invalid_argument("spot light: cone angle must be positive");
    return std::make_shared<SphereLight>(p, radius, L, axis, coneAngle, softness);
}
LightPtr makeRectLight(const Affine& m, double w, double h, const Spectrum& L) {
    return std::make_shared<PlanarLight>(m, false, w, h, L);
}
LightPtr makeDiskLight(const Affine& m, double r, const Spectrum& L) { return std::make_shared<PlanarLight>(m, true, r, r, L); }
LightPtr makeDomeLight(const Spectrum& L, LatLongImage image, const Affine& m) {
    return std::make_shared<DomeLight>(L, std::move(image), m);
}

LightPtr makeMeshLight(const std::string& name, std::vector<Vec3> points, const std::vector<uint32_t>& indices,
                       const Spectrum& radiance) {
    auto light = std::make_shared<MeshLight>(name, std::move(points), indices, radiance);
    return light->empty() ? nullptr : light;
}

}  // namespace volphoton
