// glTF 2.0 -> USD translation, shared by `volphoton gltf2usd` (usd-core front end) and the Sdf
// file-format plug-in (`references = @asset.glb@` in usdview / usdrecord).
//
// The translator reads the asset with tinygltf and writes the USD layer as usda text, so it needs
// no USD types: the front end hands the text to usd-core (Sdf.Layer.ImportFromString) and the plug-in
// to SdfFileFormat "usda" (ReadFromString). Both therefore get the same prims, bit for bit.
//
// What is translated (glTF 2.0 spec, https://registry.khronos.org/glTF/specs/2.0/glTF-2.0.html):
//   | glTF                                   | USD                                                    |
//   |----------------------------------------|--------------------------------------------------------|
//   | asset (glTF is +Y up, metres)          | layer upAxis = "Y", metersPerUnit = 1, defaultPrim      |
//   | scene (one)                            | children of the default prim                           |
//   | scenes (several)                       | variant set "scene" on the default prim, one variant   |
//   |                                        | per scene, selection = glTF `scene` (else the first)   |
//   | node                                   | Xform; matrix -> xformOp:transform (matrix4d),         |
//   |                                        | TRS -> xformOp:translate (double3), :orient (quatd),   |
//   |                                        | :scale (double3), in that order (T * R * S)            |
//   | mesh (used by one node)                | Mesh prim under that node's Xform                      |
//   | mesh (used by several nodes)           | class prim under /<root>/Prototypes, referenced        |
//   | primitives (triangles, strip, fan)     | merged into one Mesh (faceVertexCounts all 3)          |
//   | POSITION / NORMAL / TEXCOORD_0         | points / normals (vertex) / primvars:st (vertex,       |
//   |                                        | t = 1 - v: glTF's UV origin is top left)               |
//   | COLOR_0                                | primvars:displayColor (+displayOpacity), vertex        |
//   | material per primitive                 | GeomSubset (familyName materialBind, partition) per    |
//   |                                        | material when primitives differ; else a prim binding   |
//   | material pbrMetallicRoughness factors  | Material + UsdPreviewSurface (diffuseColor, opacity,   |
//   |                                        | metallic, roughness, emissiveColor); displayColor      |
//   | any accessor component type            | float (normalized integers per the spec's formulas),   |
//   |                                        | sparse accessors applied                               |
//
// Not translated (warnings): textures (factors are used), skins, morph targets, animations,
// cameras, KHR_lights_punctual. Points and lines are errors for their primitive (skipped).
// Every problem is reported with the file and the element (`meshes[2].primitives[0]`, ...).
#pragma once

#include <cstddef>
#include <string>
#include <vector>

namespace volphoton::gltf {

enum class Severity { Warning, Error };

struct Diagnostic {
    Severity severity;
    std::string element;  ///< glTF element, e.g. "accessors[3]" or "meshes[0].primitives[1]"; "" for the file
    std::string message;
};

struct Translation {
    /// false: nothing could be translated (unreadable file); usda is empty. true: usda holds the layer,
    /// possibly without the elements that have an Error diagnostic.
    bool ok = false;
    std::string usda;
    std::vector<Diagnostic> diagnostics;
    std::size_t triangles = 0;
    std::size_t meshPrims = 0;
    std::size_t nodePrims = 0;
};

struct Options {
    /// Name of the default prim; "" derives it from the file name (sanitized to a USD identifier).
    std::string rootName;
};

/// Reads a .gltf or .glb file (chosen by the file's first bytes, not its extension) and translates
/// it. Never throws for bad input: every problem becomes a Diagnostic.
Translation translateFile(const std::string& path, const Options& options = {});

/// A valid USD prim name made from `name` ("" -> fallback).
std::string makeIdentifier(const std::string& name, const std::string& fallback);

}  // namespace volphoton::gltf
