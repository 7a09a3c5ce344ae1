#include "hd/implicitSurfaceSceneIndexPlugin.h"

#include "pxr/imaging/hd/retainedDataSource.h"
#include "pxr/imaging/hd/sceneIndexPluginRegistry.h"
#include "pxr/imaging/hd/tokens.h"
#include "pxr/imaging/hdsi/implicitSurfaceSceneIndex.h"

#include <array>

PXR_NAMESPACE_OPEN_SCOPE

namespace {

/// The type name the plug-in is registered under (the key in plugInfo.json).
TfToken const &_TypeName() {
    static TfToken const name("HdVolPhoton_ImplicitSurfaceSceneIndexPlugin");
    return name;
}

/// HdsiImplicitSurfaceSceneIndex's arguments: every implicit type the delegate meets, to a mesh.
HdContainerDataSourceHandle _ToMeshArguments() {
    std::array<TfToken, 5> const types = {HdPrimTypeTokens->sphere, HdPrimTypeTokens->cube, HdPrimTypeTokens->cone,
                                          HdPrimTypeTokens->cylinder, HdPrimTypeTokens->capsule};
    HdDataSourceBaseHandle const mesh = HdRetainedTypedSampledDataSource<TfToken>::New(HdsiImplicitSurfaceSceneIndexTokens->toMesh);
    std::array<HdDataSourceBaseHandle, 5> values;
    values.fill(mesh);
    return HdRetainedContainerDataSource::New(types.size(), types.data(), values.data());
}

}  // namespace

TF_REGISTRY_FUNCTION(TfType) { HdSceneIndexPluginRegistry::Define<HdVolPhoton_ImplicitSurfaceSceneIndexPlugin>(); }

TF_REGISTRY_FUNCTION(HdSceneIndexPlugin) {
    // For the renderer whose plugInfo displayName is "VolPhoton", first in phase 0, so that every
    // later scene index already sees meshes.
    HdSceneIndexPluginRegistry::GetInstance().RegisterSceneIndexForRenderer(
        "VolPhoton", _TypeName(), _ToMeshArguments(), /*insertionPhase=*/0, HdSceneIndexPluginRegistry::InsertionOrderAtStart);
}

HdVolPhoton_ImplicitSurfaceSceneIndexPlugin::HdVolPhoton_ImplicitSurfaceSceneIndexPlugin() = default;

HdSceneIndexBaseRefPtr HdVolPhoton_ImplicitSurfaceSceneIndexPlugin::_AppendSceneIndex(
    HdSceneIndexBaseRefPtr const &inputScene, HdContainerDataSourceHandle const &inputArgs) {
    return HdsiImplicitSurfaceSceneIndex::New(inputScene, inputArgs);
}

PXR_NAMESPACE_CLOSE_SCOPE
