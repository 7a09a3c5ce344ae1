// Cameras: perspective (with thin-lens depth of field) and orthographic.
//
// | field          | type   | default | units        | meaning                                          |
// |----------------|--------|---------|--------------|--------------------------------------------------|
// | cameraToWorld  | Affine | identity|              | camera looks down -Z, +Y up (USD convention)      |
// | projection     | enum   | Persp.  |              | Perspective or Orthographic                       |
// | tanHalfFovX    | double | 0.5     |              | perspective: tan of half the horizontal view angle|
// | orthoWidth     | double | 2       | scene units  | orthographic: width of the view                   |
// | lensRadius     | double | 0       | scene units  | thin-lens aperture radius (0: pinhole)            |
// | focusDistance  | double | 1       | scene units  | distance of the plane in focus                    |
// | nearClip/farClip| double| 0 / inf | scene units  | ray interval                                      |
// The vertical extent follows from the image aspect ratio (square pixels).
#pragma once

#include "core/math.h"

namespace volphoton {

struct CameraDesc {
    enum class Projection { Perspective, Orthographic };
    Affine cameraToWorld;
    Projection projection = Projection::Perspective;
    double tanHalfFovX = 0.5;
    double orthoWidth = 2.0;
    double lensRadius = 0.0;
    double focusDistance = 1.0;
    double nearClip = 0.0;
    double farClip = Infinity;
};

/// \class Camera
/// Generates primary rays; immutable and thread-safe.
class Camera {
public:
    Camera(const CameraDesc& desc, int width, int height);
    /// Ray through image position (px, py) in pixels (0,0 top-left), lens sample (u1, u2).
    /// Returns the ray and its valid interval [tMin, tMax].
    Ray generateRay(double px, double py, double u1, double u2, double* tMin, double* tMax) const;
    /// Where world point p images, in generateRay's pixel coordinates: set when p is in front of a
    /// pinhole or orthographic camera and inside the image (a thin lens blurs a point's image: false).
    bool project(const Vec3& p, double* px, double* py) const;
    Vec3 position() const { return desc_.cameraToWorld.point(Vec3()); }
    int width() const { return width_; }
    int height() const { return height_; }

private:
    CameraDesc desc_;
    int width_, height_;
};

}  // namespace volphoton
