// hdVolPhoton: Gf <-> core value conversions shared by the Hydra prims.
#ifndef HDVOLPHOTON_CONVERSIONS_H
#define HDVOLPHOTON_CONVERSIONS_H

#include "pxr/pxr.h"
#include "pxr/base/gf/matrix4d.h"
#include "pxr/base/gf/vec3f.h"

#include "core/math.h"

PXR_NAMESPACE_OPEN_SCOPE

/// GfMatrix4d uses row vectors (p' = p M, translation in row 3); the core's Affine uses column
/// vectors, so it is the transpose of the upper 3x4 block.
inline volphoton::Affine HdVolPhoton_ToAffine(GfMatrix4d const &m) {
    volphoton::Affine a;
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 4; ++c) a.m[r][c] = m[c][r];
    return a;
}

inline volphoton::Spectrum HdVolPhoton_ToSpectrum(GfVec3f const &v) { return {v[0], v[1], v[2]}; }

PXR_NAMESPACE_CLOSE_SCOPE

#endif  // HDVOLPHOTON_CONVERSIONS_H
