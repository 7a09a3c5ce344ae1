#include "fileFormat.h"

#include "gltf/gltfToUsda.h"

#include "pxr/base/tf/diagnostic.h"
#include "pxr/base/tf/registryManager.h"
#include "pxr/base/tf/type.h"

#include <cctype>
#include <fstream>

PXR_NAMESPACE_OPEN_SCOPE

TF_REGISTRY_FUNCTION(TfType) {
    SDF_DEFINE_FILE_FORMAT(UsdVolPhotonGltfFileFormat, SdfFileFormat);
}

UsdVolPhotonGltfFileFormat::UsdVolPhotonGltfFileFormat()
    : SdfFileFormat(TfToken("gltf"), TfToken("2.0"), TfToken("usd"), std::vector<std::string>{"gltf", "glb"}) {}

UsdVolPhotonGltfFileFormat::~UsdVolPhotonGltfFileFormat() = default;

bool UsdVolPhotonGltfFileFormat::CanRead(const std::string& file) const {
    // A .glb starts with "glTF"; a .gltf is JSON. The translator tells the two apart itself.
    std::ifstream in(file, std::ios::binary);
    char first = 0;
    while (in.get(first) && std::isspace(static_cast<unsigned char>(first))) {}
    return first == '{' || first == 'g';
}

bool UsdVolPhotonGltfFileFormat::Read(SdfLayer* layer, const std::string& resolvedPath,
                                      bool /*metadataOnly: the whole asset is translated*/) const {
    // XXX: reads the file system only; a glTF inside a package (.usdz) or behind a custom
    // ArResolver is not supported yet (tinygltf needs a path to find external buffers).
    const volphoton::gltf::Translation t = volphoton::gltf::translateFile(resolvedPath);
    for (const volphoton::gltf::Diagnostic& d : t.diagnostics) {
        const std::string where = d.element.empty() ? resolvedPath : resolvedPath + ": " + d.element;
        if (d.severity == volphoton::gltf::Severity::Error)
            TF_RUNTIME_ERROR("%s: %s", where.c_str(), d.message.c_str());
        else
            TF_WARN("%s: %s", where.c_str(), d.message.c_str());
    }
    if (!t.ok) return false;
    // The "usda" format (UsdUsdaFileFormat, from the usd library's plug-in), not Sdf's base text
    // format "sdf", whose magic cookie is "#sdf".
    static const TfToken usdaId("usda");
    SdfFileFormatConstPtr usda = SdfFileFormat::FindById(usdaId);
    if (!usda) {
        TF_RUNTIME_ERROR("%s: the usda file format is not registered", resolvedPath.c_str());
        return false;
    }
    return usda->ReadFromString(layer, t.usda);
}

PXR_NAMESPACE_CLOSE_SCOPE
