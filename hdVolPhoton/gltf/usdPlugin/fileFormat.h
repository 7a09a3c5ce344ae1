// Sdf file-format plug-in: glTF 2.0 (.gltf, .glb) as USD layers, so that `references = @asset.glb@`
// works in usdview, usdrecord and any OpenUSD application that loads this plug-in.
#pragma once

#include "pxr/pxr.h"
#include "pxr/usd/sdf/fileFormat.h"

PXR_NAMESPACE_OPEN_SCOPE

/// \class UsdVolPhotonGltfFileFormat
///
/// Reads .gltf/.glb files through the same translator as `volphoton gltf2usd`
/// (hdVolPhoton/gltf/gltfToUsda.h, mapping table there): the asset becomes usda text, which the
/// usda file format parses into the layer. Read-only: writing a layer as glTF is an error.
/// Translation problems are posted as TF warnings naming the file and the glTF element; an
/// unreadable file is a TF runtime error and the layer fails to open.
///
/// Threading: Read may be called from several threads for different files (the translator keeps
/// no shared state).
class UsdVolPhotonGltfFileFormat : public SdfFileFormat {
public:
    bool CanRead(const std::string& file) const override;
    bool Read(SdfLayer* layer, const std::string& resolvedPath, bool metadataOnly) const override;

protected:
    SDF_FILE_FORMAT_FACTORY_ACCESS;

    UsdVolPhotonGltfFileFormat();
    ~UsdVolPhotonGltfFileFormat() override;
};

PXR_NAMESPACE_CLOSE_SCOPE
