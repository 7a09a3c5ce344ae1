#include "core/camera.h"

#include <stdexcept>

namespace volphoton {

Camera::Camera(const CameraDesc& desc, int width, int height) : desc_(desc), width_(width), height_(height) {
    if (width <= 0 || height <= 0) throw std::invalid_argument("camera: resolution must be positive");
    if (!desc.cameraToWorld.inverse()) throw std::invalid_argument("camera: cameraToWorld is not invertible or not finite");
    if (!(desc.tanHalfFovX > 0) || !std::isfinite(desc.tanHalfFovX)) throw std::invalid_argument("camera: field of view must be positive");
    if (!(desc.orthoWidth > 0)) throw std::invalid_argument("camera: orthoWidth must be positive");
    if (!(desc.lensRadius >= 0) || !(desc.focusDistance > 0)) throw std::invalid_argument("camera: lens radius must be >= 0 and focus distance > 0");
}

Ray Camera::generateRay(double px, double py, double u1, double u2, double* tMin, double* tMax) const {
    // Screen coordinates in [-1, 1] horizontally; vertical scaled by the aspect ratio.
    double sx = 2.0 * px / width_ - 1.0;
    double sy = (1.0 - 2.0 * py / height_) * static_cast<double>(height_) / width_;
    Vec3 o, d;
    if (desc_.projection == CameraDesc::Projection::Orthographic) {
        o = Vec3(sx * desc_.orthoWidth / 2, sy * desc_.orthoWidth / 2, 0);
        d = Vec3(0, 0, -1);
    } else {
        d = normalize(Vec3(sx * desc_.tanHalfFovX, sy * desc_.tanHalfFovX, -1));
        if (desc_.lensRadius > 0) {
            // Thin lens: concentric-free polar sample of the aperture, rays through the focus point.
            double r = desc_.lensRadius * std::sqrt(u1), phi = 2 * Pi * u2;
            Vec3 lens(r * std::cos(phi), r * std::sin(phi), 0);
            Vec3 focus = d * (desc_.focusDistance / -d.z);
            o = lens;
            d = normalize(focus - lens);
        }
    }
    Vec3 wd = desc_.cameraToWorld.vector(d);
    double scale = length(wd);  // clip distances are along the camera's -Z axis in camera space
    Ray ray{desc_.cameraToWorld.point(o), wd / scale};
    double cosZ = -d.z;
    *tMin = desc_.nearClip / cosZ * scale;
    *tMax = desc_.farClip / cosZ * scale;
    return ray;
}

bool Camera::project(const Vec3& p, double* px, double* py) const {
    if (desc_.lensRadius > 0) return false;
    std::optional<Affine> toCamera = desc_.cameraToWorld.inverse();
    if (!toCamera) return false;
    Vec3 q = toCamera->point(p);
    if (!(q.z < 0) || !isFinite(q)) return false;
    double half = desc_.projection == CameraDesc::Projection::Orthographic ? desc_.orthoWidth / 2 : desc_.tanHalfFovX * -q.z;
    double sx = q.x / half, sy = q.y / half;  // generateRay's screen coordinates, inverted
    *px = (sx + 1) * width_ / 2;
    *py = (1 - sy * width_ / static_cast<double>(height_)) * height_ / 2;
    return *px >= 0 && *px < width_ && *py >= 0 && *py < height_;
}

}  // namespace volphoton
