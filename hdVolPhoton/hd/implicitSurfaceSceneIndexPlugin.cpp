#include "hd/implicitSurfaceSceneIndexPlugin.h"

#include "pxr/imaging/hd/retainedDataSource.h"
#include "pxr/imaging/hd/sceneIndexPluginRegistry.h"
#include "pxr/imaging/hd/tokens.h"
#include "pxr/imaging/hdsi/implicitSurfaceSceneIndex.h"

PXR_NAMESPACE_OPEN_SCOPE

namespace {
TfToken const &_PluginName() {
    static TfToken const name("HdVolPhoton_ImplicitSurfaceSceneIndexPlugin");
    return name;
}
char const *const _rendererDisplayName = "VolPhoton";  // plugInfo.json's displayName of the renderer
}  // namespace

TF_REGISTRY_FUNCTION(TfType) { HdSceneIndexPluginRegistry::Define<HdVolPhoton_ImplicitSurfaceSceneIndexPlugin>(); }

TF_REGISTRY_FUNCTION(HdSceneIndexPlugin) {
    HdDataSourceBaseHandle const toMesh =
        HdRetainedTypedSampledDataSource<TfToken>::New(HdsiImplicitSurfaceSceneIndexTokens->toMesh);
    HdContainerDataSourceHandle const inputArgs =
        HdRetainedContainerDataSource::New(HdPrimTypeTokens->sphere, toMesh, HdPrimTypeTokens->cube, toMesh,
                                           HdPrimTypeTokens->cone, toMesh, HdPrimTypeTokens->cylinder, toMesh,
                                           HdPrimTypeTokens->capsule, toMesh);
    HdSceneIndexPluginRegistry::GetInstance().RegisterSceneIndexForRenderer(
        _rendererDisplayName, _PluginName(), inputArgs, 0, HdSceneIndexPluginRegistry::InsertionOrderAtStart);
}

HdVolPhoton_ImplicitSurfaceSceneIndexPlugin::HdVolPhoton_ImplicitSurfaceSceneIndexPlugin() = default;

HdSceneIndexBaseRefPtr HdVolPhoton_ImplicitSurfaceSceneIndexPlugin::_AppendSceneIndex(
    HdSceneIndexBaseRefPtr const &inputScene, HdContainerDataSourceHandle const &inputArgs) {
    return HdsiImplicitSurfaceSceneIndex::New(inputScene, inputArgs);
}

PXR_NAMESPACE_CLOSE_SCOPE
