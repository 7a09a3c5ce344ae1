// hdVolPhoton: the scene-index plug-in that turns implicit surfaces into meshes.
#ifndef HDVOLPHOTON_IMPLICIT_SURFACE_SCENE_INDEX_PLUGIN_H
#define HDVOLPHOTON_IMPLICIT_SURFACE_SCENE_INDEX_PLUGIN_H

#include "pxr/pxr.h"
#include "pxr/imaging/hd/sceneIndexPlugin.h"

PXR_NAMESPACE_OPEN_SCOPE

/// \class HdVolPhoton_ImplicitSurfaceSceneIndexPlugin
///
/// Only for the scene-index path (USDIMAGINGGL_ENGINE_ENABLE_SCENE_INDEX=1 in OpenUSD 24.08): there
/// sphere, cube, cone, cylinder and capsule prims reach the render index as implicit prims, which
/// the delegate does not support, so they were dropped. This plug-in (hdEmbree solves the same
/// problem the same way, through the scene-index plug-in registry) appends
/// HdsiImplicitSurfaceSceneIndex to turn them into meshes, as the legacy scene delegate's adapters
/// do when the delegate does not support the implicit type. Loaded with the VolPhoton renderer.
class HdVolPhoton_ImplicitSurfaceSceneIndexPlugin : public HdSceneIndexPlugin
{
public:
    HdVolPhoton_ImplicitSurfaceSceneIndexPlugin();

protected:
    HdSceneIndexBaseRefPtr _AppendSceneIndex(HdSceneIndexBaseRefPtr const &inputScene,
                                             HdContainerDataSourceHandle const &inputArgs) override;
};

PXR_NAMESPACE_CLOSE_SCOPE

#endif  // HDVOLPHOTON_IMPLICIT_SURFACE_SCENE_INDEX_PLUGIN_H
