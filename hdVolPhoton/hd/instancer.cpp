#include "hd/instancer.h"

#include "pxr/base/gf/quatd.h"
#include "pxr/base/gf/rotation.h"
#include "pxr/imaging/hd/renderIndex.h"
#include "pxr/imaging/hd/sceneDelegate.h"
#include "pxr/imaging/hd/tokens.h"

PXR_NAMESPACE_OPEN_SCOPE

HdVolPhotonInstancer::HdVolPhotonInstancer(HdSceneDelegate *delegate, SdfPath const &id) : HdInstancer(delegate, id) {}

HdVolPhotonInstancer::~HdVolPhotonInstancer() = default;

void HdVolPhotonInstancer::Sync(HdSceneDelegate *sceneDelegate, HdRenderParam *renderParam, HdDirtyBits *dirtyBits) {
    _UpdateInstancer(sceneDelegate, dirtyBits);
    if (HdChangeTracker::IsAnyPrimvarDirty(*dirtyBits, GetId())) {
        SdfPath const &id = GetId();
        auto pull = [&](TfToken const &name, auto *out) {
            VtValue v = sceneDelegate->Get(id, name);
            using T = std::decay_t<decltype(*out)>;
            *out = v.IsHolding<T>() ? v.UncheckedGet<T>() : T();
        };
        pull(HdInstancerTokens->instanceTransforms, &_transforms);
        pull(HdInstancerTokens->instanceTranslations, &_translations);
        pull(HdInstancerTokens->instanceRotations, &_rotations);
        pull(HdInstancerTokens->instanceScales, &_scales);
    }
    *dirtyBits = HdChangeTracker::Clean;
}

VtMatrix4dArray HdVolPhotonInstancer::ComputeInstanceTransforms(SdfPath const &prototypeId) {
    GfMatrix4d instancerXf = GetDelegate()->GetInstancerTransform(GetId());
    VtIntArray indices = GetDelegate()->GetInstanceIndices(GetId(), prototypeId);
    VtMatrix4dArray out(indices.size());
    for (size_t i = 0; i < indices.size(); ++i) {
        size_t k = static_cast<size_t>(indices[i]);
        // Scale, rotate, translate, then the authored instance transform (UsdGeomPointInstancer order).
        GfMatrix4d m(1.0);
        if (k < _scales.size()) m *= GfMatrix4d(1.0).SetScale(GfVec3d(_scales[k]));
        if (k < _rotations.size()) m *= GfMatrix4d(1.0).SetRotate(GfRotation(GfQuatd(_rotations[k])));
        if (k < _translations.size()) m *= GfMatrix4d(1.0).SetTranslate(GfVec3d(_translations[k]));
        if (k < _transforms.size()) m *= _transforms[k];
        out[i] = m * instancerXf;
    }
    if (GetParentId().IsEmpty()) return out;
    // Nested instancing: every instance of this instancer under every instance of its parent.
    HdInstancer *parent = GetDelegate()->GetRenderIndex().GetInstancer(GetParentId());
    if (!parent) return out;
    VtMatrix4dArray parents = static_cast<HdVolPhotonInstancer *>(parent)->ComputeInstanceTransforms(GetId());
    VtMatrix4dArray nested;
    nested.reserve(out.size() * parents.size());
    for (GfMatrix4d const &p : parents)
        for (GfMatrix4d const &m : out) nested.push_back(m * p);
    return nested;
}

PXR_NAMESPACE_CLOSE_SCOPE
