// UsdPreviewSurface inputs -> the renderer's surface material: the one set of rules both front
// ends apply (the usd-core reader in volphoton/usdscene.py and the Hydra material prim).
//
// | inputs                                      | surface                                      |
// |---------------------------------------------|----------------------------------------------|
// | opacityThreshold > 0 and opacity below it   | not rendered (cutout)                        |
// | opacity <= 1e-3 and an authored ior > 1     | smooth dielectric with that ior (clear glass)|
// | opacity <= 1e-3 otherwise                   | not rendered (fully transparent)             |
// | otherwise                                   | lambertian: diffuseColor clamped to [0, 1],  |
// |                                             | emissiveColor (negative -> 0) as emission    |
// Partial opacity and metallic > 0 render opaque diffuse (noted). Non-finite colours use the
// UsdPreviewSurface defaults (diffuse 0.18, emission 0) (noted).
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "core/scene.h"

namespace volphoton {

struct PreviewSurfaceInputs {
    Spectrum diffuseColor{0.18};
    Spectrum emissiveColor{0.0};
    double opacity = 1.0;
    double opacityThreshold = 0.0;
    double ior = 1.5;
    bool iorAuthored = false;
    double metallic = 0.0;
};

/// Something a front end should report, naming the shader input (e.g. "diffuseColor").
struct PreviewSurfaceNote {
    bool error;  ///< an unusable value (else a warning: changed or unsupported)
    std::string input;
    std::string message;
};

/// The material, or nullopt when the surface is not rendered.
std::optional<SurfaceMaterial> previewSurfaceMaterial(const PreviewSurfaceInputs& in,
                                                      std::vector<PreviewSurfaceNote>* notes);

}  // namespace volphoton
