// glTF 2.0 -> usda text. See gltfToUsda.h for the mapping table.
#include "gltfToUsda.h"

#include <tiny_gltf.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

namespace volphoton::gltf {

std::string makeIdentifier(const std::string& name, const std::string& fallback) {
    std::string id;
    for (char c : name) {
        const bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_';
        id += ok ? c : '_';
    }
    if (id.empty() || std::all_of(id.begin(), id.end(), [](char c) { return c == '_'; })) id = fallback;
    if (id[0] >= '0' && id[0] <= '9') id = "_" + id;
    return id;
}

namespace {

using tinygltf::Accessor;
using tinygltf::Model;

constexpr int kMaxNodeDepth = 1000;  // deeper hierarchies are treated as malformed (and cycles are caught)

std::string at(const std::string& array, std::size_t index) { return array + "[" + std::to_string(index) + "]"; }

/// `s` with every byte that is not part of a well-formed UTF-8 sequence replaced by '?' (messages and
/// glTF names may quote raw bytes of a corrupt file; usda and Python want valid UTF-8).
std::string validUtf8(const std::string& s) {
    std::string out;
    out.reserve(s.size());
    for (std::size_t i = 0; i < s.size();) {
        const unsigned char c = static_cast<unsigned char>(s[i]);
        const int length = c < 0x80 ? 1 : (c >> 5) == 0x6 ? 2 : (c >> 4) == 0xe ? 3 : (c >> 3) == 0x1e ? 4 : 0;
        bool ok = length > 0 && i + length <= s.size();
        for (int k = 1; ok && k < length; ++k) ok = (static_cast<unsigned char>(s[i + k]) & 0xc0) == 0x80;
        if (ok && length > 1) {  // reject overlong forms and code points past U+10FFFF (RFC 3629)
            const unsigned char c1 = static_cast<unsigned char>(s[i + 1]);
            ok = !(c < 0xc2 && length == 2) && !(c == 0xe0 && c1 < 0xa0) && !(c == 0xed && c1 >= 0xa0) &&
                 !(c == 0xf0 && c1 < 0x90) && !(c == 0xf4 && c1 >= 0x90) && c <= 0xf4;
        }
        if (ok) {
            out.append(s, i, length);
            i += length;
        } else {
            out += '?';
            ++i;
        }
    }
    return out;
}

class Reporter {
public:
    explicit Reporter(std::vector<Diagnostic>& out) : _out(out) {}
    void warn(const std::string& element, const std::string& message) { add(Severity::Warning, element, message); }
    void error(const std::string& element, const std::string& message) { add(Severity::Error, element, message); }

private:
    void add(Severity s, const std::string& element, const std::string& message) {
        // One line per distinct problem: a file with 10,000 textured materials says so once each.
        if (_seen.insert(element + "\n" + message).second) _out.push_back({s, validUtf8(element), validUtf8(message)});
    }
    std::vector<Diagnostic>& _out;
    std::set<std::string> _seen;
};

// ---- accessors -------------------------------------------------------------------------------------

/// One component at p as an exact double (every glTF component type fits in a double).
double rawComponent(const unsigned char* p, int componentType) {
    auto load = [p](auto v) { std::memcpy(&v, p, sizeof v); return static_cast<double>(v); };
    switch (componentType) {
    case TINYGLTF_COMPONENT_TYPE_BYTE: return load(std::int8_t{});
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return load(std::uint8_t{});
    case TINYGLTF_COMPONENT_TYPE_SHORT: return load(std::int16_t{});
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: return load(std::uint16_t{});
    case TINYGLTF_COMPONENT_TYPE_INT: return load(std::int32_t{});
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: return load(std::uint32_t{});
    case TINYGLTF_COMPONENT_TYPE_FLOAT: return load(float{});
    case TINYGLTF_COMPONENT_TYPE_DOUBLE: return load(double{});
    default: return 0.0;
    }
}

/// A raw component as the float the spec defines: normalized integers map to [0, 1] or [-1, 1]
/// ("Accessor data types", glTF 2.0 section 3.11: f = max(c / (2^(b-1) - 1), -1) signed, c / (2^b - 1)
/// unsigned), computed in float so it is exactly reproducible.
float toFloat(double raw, int componentType, bool normalized) {
    if (!normalized) return static_cast<float>(raw);
    const float c = static_cast<float>(raw);
    switch (componentType) {
    case TINYGLTF_COMPONENT_TYPE_BYTE: return std::max(c / 127.0f, -1.0f);
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return c / 255.0f;
    case TINYGLTF_COMPONENT_TYPE_SHORT: return std::max(c / 32767.0f, -1.0f);
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: return c / 65535.0f;
    default: return c;
    }
}

/// Bytes [offset, offset + length) of bufferViews[index], checked against its buffer.
bool viewBytes(const Model& model, int index, std::size_t offset, std::size_t length, const std::string& element,
               Reporter& rep, const unsigned char*& data) {
    if (index < 0 || static_cast<std::size_t>(index) >= model.bufferViews.size()) {
        rep.error(element, "bufferView " + std::to_string(index) + " does not exist");
        return false;
    }
    const tinygltf::BufferView& bv = model.bufferViews[index];
    const std::string bvName = at("bufferViews", index);
    if (bv.buffer < 0 || static_cast<std::size_t>(bv.buffer) >= model.buffers.size()) {
        rep.error(bvName, "buffer " + std::to_string(bv.buffer) + " does not exist");
        return false;
    }
    const std::vector<unsigned char>& buffer = model.buffers[bv.buffer].data;
    if (bv.byteOffset > buffer.size() || bv.byteLength > buffer.size() - bv.byteOffset) {
        rep.error(bvName, "bytes " + std::to_string(bv.byteOffset) + ".." + std::to_string(bv.byteOffset + bv.byteLength) +
                              " lie outside buffers[" + std::to_string(bv.buffer) + "] (" +
                              std::to_string(buffer.size()) + " bytes; missing or truncated buffer?)");
        return false;
    }
    if (offset > bv.byteLength || length > bv.byteLength - offset) {
        rep.error(element, "reads bytes " + std::to_string(offset) + ".." + std::to_string(offset + length) + " of " +
                               bvName + ", which has " + std::to_string(bv.byteLength));
        return false;
    }
    data = buffer.data() + bv.byteOffset + offset;
    return true;
}

/// accessors[index] as exact doubles, count * components values, sparse substitution applied.
/// `allowedComponents` lists the element sizes the caller accepts (3 for VEC3, ...).
bool readRaw(const Model& model, int index, std::initializer_list<int> allowedComponents, const std::string& user,
             Reporter& rep, std::vector<double>& out, int& components) {
    if (index < 0 || static_cast<std::size_t>(index) >= model.accessors.size()) {
        rep.error(user, "accessor " + std::to_string(index) + " does not exist");
        return false;
    }
    const Accessor& acc = model.accessors[index];
    const std::string name = at("accessors", index);
    components = tinygltf::GetNumComponentsInType(static_cast<std::uint32_t>(acc.type));
    const int componentSize = tinygltf::GetComponentSizeInBytes(static_cast<std::uint32_t>(acc.componentType));
    if (components <= 0 || componentSize <= 0) {
        rep.error(name, "unknown type " + std::to_string(acc.type) + " or componentType " + std::to_string(acc.componentType));
        return false;
    }
    if (std::find(allowedComponents.begin(), allowedComponents.end(), components) == allowedComponents.end()) {
        rep.error(name, "has " + std::to_string(components) + " components per element, which " + user + " cannot use");
        return false;
    }
    const std::size_t elementSize = static_cast<std::size_t>(components) * componentSize;
    if (acc.count > (std::size_t(1) << 31) / static_cast<std::size_t>(components)) {
        rep.error(name, "count " + std::to_string(acc.count) + " is too large");
        return false;
    }
    out.assign(acc.count * components, 0.0);  // no bufferView: zeros (then sparse values), per the spec
    if (acc.bufferView >= 0 && acc.count > 0) {
        const tinygltf::BufferView* bv =
            static_cast<std::size_t>(acc.bufferView) < model.bufferViews.size() ? &model.bufferViews[acc.bufferView] : nullptr;
        const std::size_t stride = bv && bv->byteStride ? bv->byteStride : elementSize;
        if (stride < elementSize) {
            rep.error(name, "byteStride " + std::to_string(stride) + " is smaller than an element (" +
                                std::to_string(elementSize) + " bytes)");
            return false;
        }
        const unsigned char* data = nullptr;
        if (!viewBytes(model, acc.bufferView, acc.byteOffset, stride * (acc.count - 1) + elementSize, name, rep, data))
            return false;
        for (std::size_t i = 0; i < acc.count; ++i)
            for (int c = 0; c < components; ++c)
                out[i * components + c] = rawComponent(data + i * stride + c * componentSize, acc.componentType);
    }
    if (acc.sparse.isSparse) {
        const std::string sparseName = name + ".sparse";
        const int n = acc.sparse.count;
        const int indexType = acc.sparse.indices.componentType;
        const int indexSize = tinygltf::GetComponentSizeInBytes(static_cast<std::uint32_t>(indexType));
        if (n < 0 || static_cast<std::size_t>(n) > acc.count ||
            (indexType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE && indexType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
             indexType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT) ||
            acc.sparse.indices.byteOffset < 0 || acc.sparse.values.byteOffset < 0) {
            rep.error(sparseName, "count, indices.componentType or a byteOffset is invalid");
            return false;
        }
        const unsigned char* indices = nullptr;
        const unsigned char* values = nullptr;
        if (!viewBytes(model, acc.sparse.indices.bufferView, acc.sparse.indices.byteOffset, std::size_t(n) * indexSize,
                       sparseName + ".indices", rep, indices) ||
            !viewBytes(model, acc.sparse.values.bufferView, acc.sparse.values.byteOffset, std::size_t(n) * elementSize,
                       sparseName + ".values", rep, values))
            return false;
        for (int k = 0; k < n; ++k) {
            const double target = rawComponent(indices + std::size_t(k) * indexSize, indexType);
            if (target >= static_cast<double>(acc.count)) {
                rep.error(sparseName + ".indices", "index " + std::to_string(static_cast<std::uint64_t>(target)) +
                                                       " is out of range (count " + std::to_string(acc.count) + ")");
                return false;
            }
            for (int c = 0; c < components; ++c)
                out[static_cast<std::size_t>(target) * components + c] =
                    rawComponent(values + std::size_t(k) * elementSize + c * componentSize, acc.componentType);
        }
    }
    return true;
}

/// A float attribute (POSITION, NORMAL, TEXCOORD_0, COLOR_0): count * components floats, all finite.
bool readFloats(const Model& model, int index, std::initializer_list<int> allowedComponents, const std::string& user,
                Reporter& rep, std::vector<float>& out, int& components) {
    std::vector<double> raw;
    if (!readRaw(model, index, allowedComponents, user, rep, raw, components)) return false;
    const Accessor& acc = model.accessors[index];
    out.resize(raw.size());
    for (std::size_t i = 0; i < raw.size(); ++i) {
        out[i] = toFloat(raw[i], acc.componentType, acc.normalized);
        if (!std::isfinite(out[i])) {
            rep.error(at("accessors", index), "value " + std::to_string(i) + " is not finite (" + user + ")");
            return false;
        }
    }
    return true;
}

bool readIndices(const Model& model, int index, std::size_t vertexCount, const std::string& user, Reporter& rep,
                 std::vector<std::uint32_t>& out) {
    std::vector<double> raw;
    int components = 0;
    if (!readRaw(model, index, {1}, user, rep, raw, components)) return false;
    const int type = model.accessors[index].componentType;
    if (type != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE && type != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
        type != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT) {
        rep.error(at("accessors", index), "indices must be unsigned byte, short or int (componentType " +
                                              std::to_string(type) + ")");
        return false;
    }
    out.resize(raw.size());
    for (std::size_t i = 0; i < raw.size(); ++i) {
        if (raw[i] >= static_cast<double>(vertexCount)) {
            rep.error(user, "index " + std::to_string(static_cast<std::uint64_t>(raw[i])) + " (at " + std::to_string(i) +
                                ") is out of range: POSITION has " + std::to_string(vertexCount) + " vertices");
            return false;
        }
        out[i] = static_cast<std::uint32_t>(raw[i]);
    }
    return true;
}

// ---- mesh assembly ---------------------------------------------------------------------------------

/// The triangle primitives of one glTF mesh merged into one vertex/index list.
struct MeshBuild {
    std::vector<float> points, normals, st, colors;  // st already flipped to USD's (s, 1 - v)
    std::vector<std::uint32_t> indices;               // 3 per triangle
    std::vector<int> faceMaterial;                    // glTF material per triangle (-1: none)
    int colorComponents = 0;                          // 3 or 4 when every primitive has COLOR_0
    bool allNormals = true, allSt = true, allColors = true;
};

/// Vertex indices of the triangles of `mode` (TRIANGLES, TRIANGLE_STRIP, TRIANGLE_FAN), glTF 2.0
/// section 3.7.2.1: strip triangle i = (v_i, v_{i+1+i%2}, v_{i+2-i%2}); fan triangle i = (v_{i+1}, v_{i+2}, v_0).
std::vector<std::uint32_t> triangulate(int mode, const std::vector<std::uint32_t>& v) {
    std::vector<std::uint32_t> tris;
    if (mode == TINYGLTF_MODE_TRIANGLES) {
        tris.assign(v.begin(), v.begin() + (v.size() / 3) * 3);
    } else if (mode == TINYGLTF_MODE_TRIANGLE_STRIP) {
        for (std::size_t i = 0; i + 2 < v.size(); ++i)
            tris.insert(tris.end(), {v[i], v[i + 1 + i % 2], v[i + 2 - i % 2]});
    } else {
        for (std::size_t i = 0; i + 2 < v.size(); ++i) tris.insert(tris.end(), {v[i + 1], v[i + 2], v[0]});
    }
    return tris;
}

void addPrimitive(const Model& model, const tinygltf::Primitive& prim, const std::string& element, Reporter& rep,
                  MeshBuild& mesh) {
    const int mode = prim.mode < 0 ? TINYGLTF_MODE_TRIANGLES : prim.mode;
    if (mode != TINYGLTF_MODE_TRIANGLES && mode != TINYGLTF_MODE_TRIANGLE_STRIP && mode != TINYGLTF_MODE_TRIANGLE_FAN) {
        static const char* names[] = {"POINTS", "LINES", "LINE_LOOP", "LINE_STRIP"};
        rep.error(element, std::string("mode ") + (mode >= 0 && mode < 4 ? names[mode] : std::to_string(mode).c_str()) +
                               " is not a triangle mode; the primitive is skipped");
        return;
    }
    auto attribute = [&](const char* name) {
        auto it = prim.attributes.find(name);
        return it == prim.attributes.end() ? -1 : it->second;
    };
    const int position = attribute("POSITION");
    if (position < 0) {
        rep.error(element, "has no POSITION attribute; the primitive is skipped");
        return;
    }
    std::vector<float> points;
    int components = 0;
    if (!readFloats(model, position, {3}, element + " POSITION", rep, points, components)) return;
    const std::size_t vertexCount = points.size() / 3;

    std::vector<std::uint32_t> vertexOrder;
    if (prim.indices >= 0) {
        if (!readIndices(model, prim.indices, vertexCount, element + " indices", rep, vertexOrder)) return;
    } else {
        vertexOrder.resize(vertexCount);
        for (std::size_t i = 0; i < vertexCount; ++i) vertexOrder[i] = static_cast<std::uint32_t>(i);
    }
    if (mode == TINYGLTF_MODE_TRIANGLES && vertexOrder.size() % 3 != 0)
        rep.warn(element, std::to_string(vertexOrder.size()) + " indices are not a multiple of 3; the last " +
                              std::to_string(vertexOrder.size() % 3) + " are ignored");
    const std::vector<std::uint32_t> tris = triangulate(mode, vertexOrder);

    // Optional attributes: each must have one element per vertex; a bad one is dropped, not the primitive.
    auto optional = [&](const char* name, std::initializer_list<int> allowed, std::vector<float>& values, int& comps) {
        const int index = attribute(name);
        if (index < 0) return false;
        if (!readFloats(model, index, allowed, element + " " + name, rep, values, comps)) return false;
        if (values.size() / comps != vertexCount) {
            rep.error(element, std::string(name) + " has " + std::to_string(values.size() / comps) + " elements for " +
                                   std::to_string(vertexCount) + " vertices; it is dropped");
            return false;
        }
        return true;
    };
    std::vector<float> normals, uv, colors;
    int normalComps = 0, uvComps = 0, colorComps = 0;
    const bool hasNormals = optional("NORMAL", {3}, normals, normalComps);
    const bool hasUv = optional("TEXCOORD_0", {2}, uv, uvComps);
    const bool hasColors = optional("COLOR_0", {3, 4}, colors, colorComps);
    if (!prim.targets.empty()) rep.warn(element, "morph targets are not translated (the base shape is used)");

    const std::uint32_t base = static_cast<std::uint32_t>(mesh.points.size() / 3);
    const bool first = mesh.points.empty() && mesh.faceMaterial.empty();
    mesh.allNormals = mesh.allNormals && hasNormals;
    mesh.allSt = mesh.allSt && hasUv;
    if (hasColors && (first || mesh.colorComponents == colorComps)) {
        mesh.colorComponents = colorComps;
    } else {
        mesh.allColors = false;
    }
    mesh.points.insert(mesh.points.end(), points.begin(), points.end());
    if (mesh.allNormals) mesh.normals.insert(mesh.normals.end(), normals.begin(), normals.end());
    if (mesh.allSt)
        for (std::size_t i = 0; i < vertexCount; ++i) mesh.st.insert(mesh.st.end(), {uv[2 * i], 1.0f - uv[2 * i + 1]});
    if (mesh.allColors) mesh.colors.insert(mesh.colors.end(), colors.begin(), colors.end());
    for (std::uint32_t i : tris) mesh.indices.push_back(base + i);
    const int material =
        prim.material >= 0 && static_cast<std::size_t>(prim.material) < model.materials.size() ? prim.material : -1;
    if (prim.material >= 0 && material < 0)
        rep.error(element, "material " + std::to_string(prim.material) + " does not exist; the primitive is unbound");
    mesh.faceMaterial.insert(mesh.faceMaterial.end(), tris.size() / 3, material);
}

// ---- usda text -------------------------------------------------------------------------------------

/// Shortest text that reads back to the same value (std::to_chars round-trips exactly).
template <class T>
void appendNumber(std::string& out, T v) {
    char buf[64];
    auto r = std::to_chars(buf, buf + sizeof buf, v);
    out.append(buf, r.ptr);
}

template <class T>
std::string scalar(T v) {
    std::string s;
    appendNumber(s, v);
    return s;
}

/// "(a, b, c)"
template <class T>
std::string tuple(const T* v, int n) {
    std::string s = "(";
    for (int i = 0; i < n; ++i) {
        if (i) s += ", ";
        appendNumber(s, v[i]);
    }
    return s + ")";
}

std::string quoted(const std::string& text) {
    std::string q = "\"";
    for (unsigned char c : validUtf8(text)) {
        if (c == '"' || c == '\\') {
            q += '\\';
            q += static_cast<char>(c);
        } else if (c < 0x20 || c == 0x7f) {
            char buf[8];
            std::snprintf(buf, sizeof buf, "\\x%02x", c);
            q += buf;
        } else {
            q += static_cast<char>(c);
        }
    }
    return q + "\"";
}

/// `customData = {string gltfName = "..."}` for prims named after a glTF element (names are sanitized).
std::vector<std::string> gltfNameMetadata(const std::string& gltfName) {
    if (gltfName.empty()) return {};
    return {"customData = {string gltfName = " + quoted(gltfName) + "}"};
}

class UsdaWriter {
public:
    std::string text;

    void line(int depth, const std::string& s) {
        text.append(std::size_t(depth) * 4, ' ');
        text += s;
        text += '\n';
    }
    /// `<header> "name" (metadata)` and the opening brace; closePrim writes the closing one.
    void openPrim(int depth, const std::string& header, const std::string& name,
                  const std::vector<std::string>& metadata = {}) {
        if (metadata.empty()) {
            line(depth, header + " " + quoted(name));
        } else {
            line(depth, header + " " + quoted(name) + " (");
            for (const std::string& m : metadata) line(depth + 1, m);
            line(depth, ")");
        }
        line(depth, "{");
    }
    void closePrim(int depth) { line(depth, "}"); }
    /// `decl = [(a, b, c), ...]` with `width` values per element (1 = scalars); primvars and normals
    /// carry their interpolation as attribute metadata.
    template <class T>
    void array(int depth, const std::string& decl, const std::vector<T>& v, int width,
               const char* interpolation = nullptr) {
        text.append(std::size_t(depth) * 4, ' ');
        text += decl + " = [";
        for (std::size_t i = 0; i < v.size(); i += width) {
            if (i) text += ", ";
            if (width > 1) text += '(';
            for (int c = 0; c < width; ++c) {
                if (c) text += ", ";
                appendNumber(text, v[i + c]);
            }
            if (width > 1) text += ')';
        }
        text += ']';
        if (interpolation) text += std::string(" (interpolation = \"") + interpolation + "\")";
        text += '\n';
    }
};

/// Unique identifiers among siblings.
class NameScope {
public:
    std::string claim(const std::string& wanted) {
        std::string name = wanted;
        for (int i = 1; !_used.insert(name).second; ++i) name = wanted + "_" + std::to_string(i);
        return name;
    }

private:
    std::set<std::string> _used;
};

class Translator {
public:
    Translator(const Model& model, const std::string& rootName, Translation& result)
        : _model(model), _root(rootName), _result(result), _rep(result.diagnostics) {}

    std::string run();

private:
    void countMeshUses(int node, int depth, std::vector<int>& onPath);
    void writeNode(int node, int depth, NameScope& siblings, std::vector<int>& onPath);
    void writeXformOps(const tinygltf::Node& node, int depth);
    bool buildMesh(int meshIndex, MeshBuild& mesh);
    void writeMesh(int meshIndex, const MeshBuild& mesh, int depth, const std::string& primName);
    void writeMaterials(int depth);
    void writeScene(int scene, int depth);
    std::string materialPath(int material) { return "/" + _root + "/Materials/" + _materialNames.at(material); }

    const Model& _model;
    std::string _root;
    Translation& _result;
    Reporter _rep;
    UsdaWriter _w;
    std::vector<int> _meshUses;
    std::map<int, MeshBuild> _meshes;        // meshes that translated (possibly partially)
    std::map<int, std::string> _prototypes;  // mesh -> prototype prim name
    std::map<int, std::string> _materialNames;
};

void Translator::countMeshUses(int node, int depth, std::vector<int>& onPath) {
    if (node < 0 || static_cast<std::size_t>(node) >= _model.nodes.size() || depth > kMaxNodeDepth ||
        std::find(onPath.begin(), onPath.end(), node) != onPath.end())
        return;  // reported by writeNode
    const tinygltf::Node& n = _model.nodes[node];
    if (n.mesh >= 0 && static_cast<std::size_t>(n.mesh) < _model.meshes.size()) ++_meshUses[n.mesh];
    onPath.push_back(node);
    for (int child : n.children) countMeshUses(child, depth + 1, onPath);
    onPath.pop_back();
}

bool Translator::buildMesh(int meshIndex, MeshBuild& mesh) {
    const tinygltf::Mesh& m = _model.meshes[meshIndex];
    for (std::size_t p = 0; p < m.primitives.size(); ++p)
        addPrimitive(_model, m.primitives[p], at("meshes", meshIndex) + at(".primitives", p), _rep, mesh);
    if (mesh.faceMaterial.empty()) {
        _rep.error(at("meshes", meshIndex), "has no triangles that could be translated; its prims are skipped");
        return false;
    }
    const std::string element = at("meshes", meshIndex);
    if (!mesh.allNormals && !mesh.normals.empty()) _rep.warn(element, "NORMAL is missing on some primitives; normals are dropped");
    if (!mesh.allSt && !mesh.st.empty()) _rep.warn(element, "TEXCOORD_0 is missing on some primitives; primvars:st is dropped");
    if (!mesh.allColors && !mesh.colors.empty())
        _rep.warn(element, "COLOR_0 is missing or differs in size on some primitives; it is dropped");
    if (!mesh.allNormals) mesh.normals.clear();
    if (!mesh.allSt) mesh.st.clear();
    if (!mesh.allColors) mesh.colors.clear();
    for (int material : mesh.faceMaterial)
        if (material >= 0 && !_materialNames.count(material)) _materialNames[material] = "";
    _result.triangles += mesh.faceMaterial.size();
    return true;
}

void Translator::writeMesh(int meshIndex, const MeshBuild& mesh, int depth, const std::string& primName) {
    const std::set<int> materials(mesh.faceMaterial.begin(), mesh.faceMaterial.end());
    const bool primBinding = materials.size() == 1 && *materials.begin() >= 0;
    std::vector<std::string> metadata = gltfNameMetadata(_model.meshes[meshIndex].name);
    if (primBinding) metadata.push_back("prepend apiSchemas = [\"MaterialBindingAPI\"]");
    _w.openPrim(depth, "def Mesh", primName, metadata);
    const int d = depth + 1;
    float lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (std::size_t i = 0; i < mesh.points.size(); ++i) {
        lo[i % 3] = std::min(lo[i % 3], mesh.points[i]);
        hi[i % 3] = std::max(hi[i % 3], mesh.points[i]);
    }
    _w.line(d, "float3[] extent = [" + tuple(lo, 3) + ", " + tuple(hi, 3) + "]");
    _w.array(d, "int[] faceVertexCounts", std::vector<int>(mesh.faceMaterial.size(), 3), 1);
    _w.array(d, "int[] faceVertexIndices", mesh.indices, 1);
    _w.array(d, "point3f[] points", mesh.points, 3);
    if (!mesh.normals.empty()) _w.array(d, "normal3f[] normals", mesh.normals, 3, "vertex");
    if (!mesh.st.empty()) _w.array(d, "texCoord2f[] primvars:st", mesh.st, 2, "vertex");

    // displayColor: vertex colours when every primitive has COLOR_0, else the materials' base colours.
    auto baseColor = [&](int material, float rgba[4]) {
        std::vector<double> f = material >= 0 ? _model.materials[material].pbrMetallicRoughness.baseColorFactor
                                              : std::vector<double>{1, 1, 1, 1};
        if (f.size() != 4) f = {1, 1, 1, 1};
        for (int c = 0; c < 4; ++c) rgba[c] = static_cast<float>(f[c]);
    };
    if (!mesh.colors.empty()) {
        const int n = mesh.colorComponents;
        std::vector<float> rgb, alpha;
        for (std::size_t i = 0; i < mesh.colors.size(); i += n) {
            rgb.insert(rgb.end(), {mesh.colors[i], mesh.colors[i + 1], mesh.colors[i + 2]});
            if (n == 4) alpha.push_back(mesh.colors[i + 3]);
        }
        _w.array(d, "color3f[] primvars:displayColor", rgb, 3, "vertex");
        if (n == 4) _w.array(d, "float[] primvars:displayOpacity", alpha, 1, "vertex");
    } else if (materials.size() == 1 && *materials.begin() < 0) {
        // No material and no COLOR_0: leave displayColor to the renderer's default.
    } else if (materials.size() == 1) {
        float rgba[4];
        baseColor(*materials.begin(), rgba);
        _w.line(d, "color3f[] primvars:displayColor = [" + tuple(rgba, 3) + "]");
    } else {
        std::vector<float> perFace;
        for (int material : mesh.faceMaterial) {
            float rgba[4];
            baseColor(material, rgba);
            perFace.insert(perFace.end(), rgba, rgba + 3);
        }
        _w.array(d, "color3f[] primvars:displayColor", perFace, 3, "uniform");
    }
    _w.line(d, "uniform token orientation = \"rightHanded\"");  // glTF front faces are counter-clockwise
    _w.line(d, "uniform token subdivisionScheme = \"none\"");

    // Materials: one binding for the prim, or a partition of GeomSubsets when primitives differ.
    if (primBinding) {
        _w.line(d, "rel material:binding = <" + materialPath(*materials.begin()) + ">");
    } else if (materials.size() > 1) {
        _w.line(d, "uniform token subsetFamily:materialBind:familyType = \"partition\"");
        NameScope subsetNames;
        for (int material : materials) {
            std::vector<int> faces;
            for (std::size_t f = 0; f < mesh.faceMaterial.size(); ++f)
                if (mesh.faceMaterial[f] == material) faces.push_back(static_cast<int>(f));
            const std::string name =
                subsetNames.claim(material >= 0 ? _materialNames.at(material) : std::string("unbound"));
            _w.openPrim(d, "def GeomSubset", name,
                        material >= 0 ? std::vector<std::string>{"prepend apiSchemas = [\"MaterialBindingAPI\"]"}
                                      : std::vector<std::string>{});
            _w.line(d + 1, "uniform token elementType = \"face\"");
            _w.line(d + 1, "uniform token familyName = \"materialBind\"");
            _w.array(d + 1, "int[] indices", faces, 1);
            if (material >= 0) _w.line(d + 1, "rel material:binding = <" + materialPath(material) + ">");
            _w.closePrim(d);
        }
    }
    _w.closePrim(depth);
}

void Translator::writeXformOps(const tinygltf::Node& n, int depth) {
    std::vector<std::string> order;
    if (n.matrix.size() == 16) {
        // glTF stores the matrix column-major for column vectors; USD's row-vector matrix has the same
        // 16 numbers row by row (the translation lands in the last row).
        std::string m = "(";
        for (int r = 0; r < 4; ++r) m += (r ? ", " : "") + tuple(n.matrix.data() + 4 * r, 4);
        _w.line(depth, "matrix4d xformOp:transform = " + m + ")");
        order.push_back("\"xformOp:transform\"");
    } else {
        if (n.translation.size() == 3) {
            _w.line(depth, "double3 xformOp:translate = " + tuple(n.translation.data(), 3));
            order.push_back("\"xformOp:translate\"");
        }
        if (n.rotation.size() == 4) {
            const double wxyz[4] = {n.rotation[3], n.rotation[0], n.rotation[1], n.rotation[2]};
            _w.line(depth, "quatd xformOp:orient = " + tuple(wxyz, 4));
            order.push_back("\"xformOp:orient\"");
        }
        if (n.scale.size() == 3) {
            _w.line(depth, "double3 xformOp:scale = " + tuple(n.scale.data(), 3));
            order.push_back("\"xformOp:scale\"");
        }
    }
    if (!order.empty()) {
        std::string list;
        for (const std::string& o : order) list += (list.empty() ? "" : ", ") + o;
        _w.line(depth, "uniform token[] xformOpOrder = [" + list + "]");
    }
}

void Translator::writeNode(int node, int depth, NameScope& siblings, std::vector<int>& onPath) {
    const std::string element = at("nodes", node);
    if (node < 0 || static_cast<std::size_t>(node) >= _model.nodes.size()) {
        _rep.error(element, "does not exist");
        return;
    }
    if (std::find(onPath.begin(), onPath.end(), node) != onPath.end() || static_cast<int>(onPath.size()) > kMaxNodeDepth) {
        _rep.error(element, "is its own ancestor (a cycle in `children`) or nested too deeply; skipped here");
        return;
    }
    const tinygltf::Node& n = _model.nodes[node];
    auto finite = [](const std::vector<double>& v) {
        return std::all_of(v.begin(), v.end(), [](double x) { return std::isfinite(x); });
    };
    if (!finite(n.matrix) || !finite(n.translation) || !finite(n.rotation) || !finite(n.scale)) {
        _rep.error(element, "has a non-finite transform; the node and its children are skipped");
        return;
    }
    if (n.skin >= 0) _rep.warn(element, "skins are not translated (the mesh is used in its bind pose)");
    if (n.camera >= 0) _rep.warn(element, "cameras are not translated");
    if (n.extensions.count("KHR_lights_punctual")) _rep.warn(element, "KHR_lights_punctual lights are not translated");

    const std::string name = siblings.claim(makeIdentifier(n.name, "node_" + std::to_string(node)));
    _w.openPrim(depth, "def Xform", name, gltfNameMetadata(n.name));
    const int d = depth + 1;
    writeXformOps(n, d);
    ++_result.nodePrims;

    NameScope children;
    if (n.mesh >= 0) {
        if (static_cast<std::size_t>(n.mesh) >= _model.meshes.size()) {
            _rep.error(element, "mesh " + std::to_string(n.mesh) + " does not exist");
        } else if (_meshes.count(n.mesh)) {
            const std::string meshName = children.claim(makeIdentifier(_model.meshes[n.mesh].name, "mesh"));
            auto proto = _prototypes.find(n.mesh);
            if (proto != _prototypes.end()) {
                _w.openPrim(d, "def Mesh", meshName,
                            {"prepend references = </" + _root + "/Prototypes/" + proto->second + ">"});
                _w.closePrim(d);
            } else {
                writeMesh(n.mesh, _meshes.at(n.mesh), d, meshName);
            }
            ++_result.meshPrims;
        }
    }
    onPath.push_back(node);
    for (int child : n.children) writeNode(child, d, children, onPath);
    onPath.pop_back();
    _w.closePrim(depth);
}

void Translator::writeMaterials(int depth) {
    if (_materialNames.empty()) return;
    NameScope names;
    for (auto& [index, name] : _materialNames)
        name = names.claim(makeIdentifier(_model.materials[index].name, "material_" + std::to_string(index)));
    _w.openPrim(depth, "def Scope", "Materials");
    for (const auto& [index, name] : _materialNames) {
        const tinygltf::Material& m = _model.materials[index];
        const std::string element = at("materials", index);
        const tinygltf::PbrMetallicRoughness& pbr = m.pbrMetallicRoughness;
        if (pbr.baseColorTexture.index >= 0 || pbr.metallicRoughnessTexture.index >= 0 || m.normalTexture.index >= 0 ||
            m.emissiveTexture.index >= 0 || m.occlusionTexture.index >= 0)
            _rep.warn(element, "textures are not translated (the factors are used)");
        std::vector<double> base = pbr.baseColorFactor.size() == 4 ? pbr.baseColorFactor : std::vector<double>{1, 1, 1, 1};
        std::vector<double> emissive = m.emissiveFactor.size() == 3 ? m.emissiveFactor : std::vector<double>{0, 0, 0};
        const std::string path = "/" + _root + "/Materials/" + name;
        const int d = depth + 1;
        _w.openPrim(d, "def Material", name, gltfNameMetadata(m.name));
        _w.line(d + 1, "token outputs:surface.connect = <" + path + "/PreviewSurface.outputs:surface>");
        _w.openPrim(d + 1, "def Shader", "PreviewSurface");
        const int s = d + 2;
        const float diffuse[3] = {float(base[0]), float(base[1]), float(base[2])};
        const float emission[3] = {float(emissive[0]), float(emissive[1]), float(emissive[2])};
        _w.line(s, "uniform token info:id = \"UsdPreviewSurface\"");
        _w.line(s, "color3f inputs:diffuseColor = " + tuple(diffuse, 3));
        _w.line(s, "color3f inputs:emissiveColor = " + tuple(emission, 3));
        _w.line(s, "float inputs:metallic = " + scalar(float(pbr.metallicFactor)));
        _w.line(s, "float inputs:roughness = " + scalar(float(pbr.roughnessFactor)));
        if (m.alphaMode == "BLEND" || m.alphaMode == "MASK")
            _w.line(s, "float inputs:opacity = " + scalar(float(base[3])));
        if (m.alphaMode == "MASK") _w.line(s, "float inputs:opacityThreshold = " + scalar(float(m.alphaCutoff)));
        _w.line(s, "token outputs:surface");
        _w.closePrim(d + 1);
        _w.closePrim(d);
    }
    _w.closePrim(depth);
}

void Translator::writeScene(int scene, int depth) {
    NameScope siblings;
    std::vector<int> onPath;
    for (int node : _model.scenes[scene].nodes) writeNode(node, depth, siblings, onPath);
}

std::string Translator::run() {
    for (const std::string& ext : _model.extensionsRequired) {
        if (ext == "KHR_mesh_quantization") continue;  // integer attributes: handled by the accessor reader
        if (ext == "KHR_draco_mesh_compression" || ext == "EXT_meshopt_compression")
            _rep.error("extensionsRequired", ext + " is not supported: compressed geometry cannot be read");
        else
            _rep.warn("extensionsRequired", ext + " is not supported; the result may differ from the asset");
    }
    if (!_model.animations.empty()) _rep.warn("animations", "animations are not translated");

    // Which meshes are translated, and which are shared by several nodes (written once, referenced).
    _meshUses.assign(_model.meshes.size(), 0);
    std::vector<int> onPath;
    for (const tinygltf::Scene& s : _model.scenes)
        for (int node : s.nodes) countMeshUses(node, 0, onPath);
    for (std::size_t m = 0; m < _model.meshes.size(); ++m) {
        if (_meshUses[m] == 0) continue;
        MeshBuild mesh;
        if (buildMesh(static_cast<int>(m), mesh)) _meshes.emplace(static_cast<int>(m), std::move(mesh));
    }
    // Material names are fixed before any binding path is written.
    UsdaWriter materialsText;
    std::swap(_w, materialsText);
    writeMaterials(1);
    std::swap(_w, materialsText);

    _w.line(0, "#usda 1.0");
    _w.line(0, "(");
    _w.line(1, "defaultPrim = " + quoted(_root));
    _w.line(1, "doc = \"Translated from glTF 2.0 by volphoton gltf2usd\"");
    _w.line(1, "metersPerUnit = 1");
    _w.line(1, "upAxis = \"Y\"");
    _w.line(0, ")");
    _w.line(0, "");

    const std::size_t sceneCount = _model.scenes.size();
    const int defaultScene =
        _model.defaultScene >= 0 && static_cast<std::size_t>(_model.defaultScene) < sceneCount ? _model.defaultScene : 0;
    std::vector<std::string> sceneNames;
    NameScope variantNames;
    for (std::size_t s = 0; s < sceneCount; ++s)
        sceneNames.push_back(variantNames.claim(makeIdentifier(_model.scenes[s].name, "scene_" + std::to_string(s))));

    if (sceneCount > 1) {
        _w.line(0, "def Xform " + quoted(_root) + " (");
        _w.line(1, "variants = {");
        _w.line(2, "string scene = " + quoted(sceneNames[defaultScene]));
        _w.line(1, "}");
        _w.line(1, "prepend variantSets = \"scene\"");
        _w.line(0, ")");
    } else {
        _w.line(0, "def Xform " + quoted(_root));
    }
    _w.line(0, "{");
    _w.text += materialsText.text;
    NameScope prototypeNames;
    bool prototypesOpen = false;
    for (auto& [index, mesh] : _meshes) {
        if (_meshUses[index] < 2) continue;
        if (!prototypesOpen) {
            _w.line(1, "class Scope \"Prototypes\"");
            _w.line(1, "{");
            prototypesOpen = true;
        }
        const std::string name = prototypeNames.claim(makeIdentifier(_model.meshes[index].name, "mesh_" + std::to_string(index)));
        _prototypes[index] = name;
        writeMesh(index, mesh, 2, name);
    }
    if (prototypesOpen) _w.line(1, "}");

    if (sceneCount == 0) {
        _rep.warn("scenes", "the file has no scenes; nothing is placed (meshes are only translated when a node uses them)");
    } else if (sceneCount == 1) {
        writeScene(0, 1);
    } else {
        _w.line(1, "variantSet \"scene\" = {");
        for (std::size_t s = 0; s < sceneCount; ++s) {
            _w.line(2, quoted(sceneNames[s]) + " {");
            writeScene(static_cast<int>(s), 3);
            _w.line(2, "}");
        }
        _w.line(1, "}");
    }
    _w.line(0, "}");
    return std::move(_w.text);
}

bool skipImage(tinygltf::Image*, const int, std::string*, std::string*, int, int, const unsigned char*, int, void*) {
    return true;  // textures are not translated: do not decode them
}

std::string stem(const std::string& path) {
    std::string base = path.substr(path.find_last_of("/\\") + 1);
    const std::size_t dot = base.find('.');
    return dot == std::string::npos ? base : base.substr(0, dot);
}

}  // namespace

Translation translateFile(const std::string& path, const Options& options) {
    Translation result;
    Reporter rep(result.diagnostics);
    std::ifstream in(path, std::ios::binary);
    if (!in) {
        rep.error("", "cannot open the file");
        return result;
    }
    char magic[4] = {};
    in.read(magic, 4);
    const bool binary = in.gcount() == 4 && std::memcmp(magic, "glTF", 4) == 0;
    in.close();

    tinygltf::Model model;
    tinygltf::TinyGLTF loader;
    loader.SetImageLoader(&skipImage, nullptr);
    std::string err, warn;
    const bool loaded = binary ? loader.LoadBinaryFromFile(&model, &err, &warn, path)
                               : loader.LoadASCIIFromFile(&model, &err, &warn, path);
    std::istringstream warnings(warn);
    for (std::string lineText; std::getline(warnings, lineText);)
        if (!lineText.empty()) rep.warn("", lineText);
    if (!loaded) {
        std::istringstream errors(err.empty() ? std::string("not a readable glTF 2.0 file") : err);
        for (std::string lineText; std::getline(errors, lineText);)
            if (!lineText.empty()) rep.error("", lineText);
        return result;
    }
    const std::string root = makeIdentifier(options.rootName.empty() ? stem(path) : options.rootName, "asset");
    result.usda = Translator(model, root, result).run();
    result.ok = true;
    return result;
}

}  // namespace volphoton::gltf
