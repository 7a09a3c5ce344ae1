// hdVolPhotonIdImages: renders a stage through UsdImagingGLEngine (no GPU) with the VolPhoton
// delegate and prints its id AOVs as JSON, for testenv/hydra/test_hydra_aovs.py. OpenUSD 24.08's
// Python cannot read an AOV render buffer (GetAovRenderBuffer is not wrapped), so this small tool
// does it in C++: HdRenderBuffer::Map.
//
//   hdVolPhotonIdImages SCENE.usda CAMERA_PATH WIDTH HEIGHT
//   hdVolPhotonIdImages SCENE.usda CAMERA_PATH WIDTH HEIGHT AOV...   (float3 AOVs instead, e.g. albedo normal)
//
// With AOV names it prints {"width", "height", "<aov>": [r, g, b, r, g, b, ...] (rows top to bottom)}.
// Prints {"width", "height", "primId": [...], "instanceId": [...], "elementId": [...] (rows top to
// bottom), "hits": [{"primId", "instanceId", "path", "instancer", "instanceIndex"}, ...]} where hits
// decodes every (primId, instanceId) pair seen with UsdImagingGLEngine::DecodeIntersection.
// The delegate's plug-in must be on PXR_PLUGINPATH_NAME. Exit 1 on any failure.
#include "pxr/pxr.h"
#include "pxr/base/gf/rect2i.h"
#include "pxr/base/gf/vec2i.h"
#include "pxr/imaging/cameraUtil/framing.h"
#include "pxr/imaging/hd/renderBuffer.h"
#include "pxr/imaging/hd/tokens.h"
#include "pxr/usd/usd/prim.h"
#include "pxr/usd/usd/stage.h"
#include "pxr/usdImaging/usdImagingGL/engine.h"

#include <chrono>
#include <cstdio>
#include <cstring>
#include <iostream>
#include <map>
#include <set>
#include <string>
#include <thread>
#include <vector>

PXR_NAMESPACE_USING_DIRECTIVE

namespace {

/// The AOV `aov` (channels values of type T a pixel, Hydra format `format`) once the render has
/// converged, rows top to bottom; empty on failure.
template <typename T>
std::vector<T> RenderAov(UsdImagingGLEngine &engine, UsdStageRefPtr const &stage, TfToken const &aov, int width,
                         int height, HdFormat format, int channels) {
    if (!engine.SetRendererAov(aov)) return {};
    UsdImagingGLRenderParams params;
    auto start = std::chrono::steady_clock::now();
    do {
        engine.Render(stage->GetPseudoRoot(), params);
        if (std::chrono::steady_clock::now() - start > std::chrono::seconds(60)) return {};
        std::this_thread::sleep_for(std::chrono::milliseconds(2));
    } while (!engine.IsConverged());
    HdRenderBuffer *buffer = engine.GetAovRenderBuffer(aov);
    if (!buffer || buffer->GetFormat() != format || buffer->GetWidth() != static_cast<unsigned>(width) ||
        buffer->GetHeight() != static_cast<unsigned>(height))
        return {};
    size_t row = static_cast<size_t>(width) * channels;
    std::vector<T> out(row * height);
    auto const *data = static_cast<T const *>(buffer->Map());
    for (int y = 0; y < height; ++y)  // Hydra's row 0 is the bottom
        std::memcpy(out.data() + y * row, data + (height - 1 - y) * row, sizeof(T) * row);
    buffer->Unmap();
    return out;
}

std::vector<int32_t> RenderIdAov(UsdImagingGLEngine &engine, UsdStageRefPtr const &stage, TfToken const &aov, int width,
                                 int height) {
    return RenderAov<int32_t>(engine, stage, aov, width, height, HdFormatInt32, 1);
}

template <typename T>
void PrintArray(char const *name, std::vector<T> const &v) {
    std::cout << "\"" << name << "\": [";
    for (size_t i = 0; i < v.size(); ++i) std::cout << (i ? "," : "") << v[i];
    std::cout << "]";
}

}  // namespace

int main(int argc, char **argv) {
    if (argc < 5) {
        std::cerr << "usage: hdVolPhotonIdImages SCENE.usda CAMERA_PATH WIDTH HEIGHT [AOV...]\n";
        return 1;
    }
    int width = std::atoi(argv[3]), height = std::atoi(argv[4]);
    UsdStageRefPtr stage = UsdStage::Open(argv[1]);
    if (!stage || width <= 0 || height <= 0) {
        std::cerr << "cannot open " << argv[1] << " or bad size\n";
        return 1;
    }
    UsdImagingGLEngine::Parameters p;
    p.gpuEnabled = false;
    UsdImagingGLEngine engine(p);
    if (!engine.SetRendererPlugin(TfToken("HdVolPhotonRendererPlugin"))) {
        std::cerr << "the VolPhoton renderer plug-in is not available (PXR_PLUGINPATH_NAME?)\n";
        return 1;
    }
    engine.SetRendererSetting(TfToken("convergedSamplesPerPixel"), VtValue(1));
    // A batch render, as usdrecord's: converged after that one pass (interactive ones refine on).
    engine.SetRendererSetting(TfToken("enableInteractive"), VtValue(false));
    engine.SetCameraPath(SdfPath(argv[2]));
    engine.SetRenderBufferSize(GfVec2i(width, height));
    engine.SetFraming(CameraUtilFraming(GfRect2i(GfVec2i(0, 0), width, height)));

    if (argc > 5) {  // float3 AOVs
        std::cout << "{\"width\": " << width << ", \"height\": " << height;
        for (int i = 5; i < argc; ++i) {
            std::vector<float> image = RenderAov<float>(engine, stage, TfToken(argv[i]), width, height, HdFormatFloat32Vec3, 3);
            if (image.empty()) {
                std::cerr << "no converged " << argv[i] << " render buffer\n";
                return 1;
            }
            std::cout << ", ";
            PrintArray(argv[i], image);
        }
        std::cout << "}" << std::endl;
        return 0;
    }
    std::map<TfToken, std::vector<int32_t>> images;
    for (TfToken const &aov : {HdAovTokens->primId, HdAovTokens->instanceId, HdAovTokens->elementId}) {
        images[aov] = RenderIdAov(engine, stage, aov, width, height);
        if (images[aov].empty()) {
            std::cerr << "no converged " << aov << " render buffer\n";
            return 1;
        }
    }
    std::cout << "{\"width\": " << width << ", \"height\": " << height << ", ";
    PrintArray("primId", images[HdAovTokens->primId]);
    std::cout << ", ";
    PrintArray("instanceId", images[HdAovTokens->instanceId]);
    std::cout << ", ";
    PrintArray("elementId", images[HdAovTokens->elementId]);
    std::cout << ", \"hits\": [";
    std::set<std::pair<int32_t, int32_t>> pairs;
    for (size_t i = 0; i < images[HdAovTokens->primId].size(); ++i)
        if (images[HdAovTokens->primId][i] >= 0)
            pairs.insert({images[HdAovTokens->primId][i], images[HdAovTokens->instanceId][i]});
    bool first = true;
    for (auto const &[primId, instanceId] : pairs) {
        unsigned char primColor[4], instanceColor[4];
        std::memcpy(primColor, &primId, 4);  // the id AOVs' byte layout (HdxPickTask's "colors")
        std::memcpy(instanceColor, &instanceId, 4);
        SdfPath path, instancer;
        int instanceIndex = -1;
        bool ok = engine.DecodeIntersection(primColor, instanceColor, &path, &instancer, &instanceIndex);
        std::cout << (first ? "" : ", ") << "{\"primId\": " << primId << ", \"instanceId\": " << instanceId
                  << ", \"decoded\": " << (ok ? "true" : "false") << ", \"path\": \"" << path.GetString()
                  << "\", \"instancer\": \"" << instancer.GetString() << "\", \"instanceIndex\": " << instanceIndex << "}";
        first = false;
    }
    std::cout << "]}" << std::endl;
    return 0;
}
