// Shared by the binding sources of volphoton._core: one registration function per topic, called in
// this order by the module entry point (bindings.cpp), and the small conversions more than one of them
// uses. Order matters: a signature names a bound type by its Python name only once that type is
// registered, so a topic that refers to another's types comes after it.
#pragma once

#include <pybind11/functional.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <memory>
#include <string>
#include <vector>

#include "converters.h"

namespace volphoton::bindings {

void bindMedia(pybind11::module_& m);           ///< phase functions, media, grid media, VDB files, blackbody (mediumBindings.cpp)
void bindScene(pybind11::module_& m);           ///< lights, camera, materials, meshes, scenes (sceneBindings.cpp)
void bindRender(pybind11::module_& m);          ///< diagnostics, render settings, film, renderer (renderBindings.cpp)
void bindImage(pybind11::module_& m);           ///< EXR/PNG output and OCIO display (imageBindings.cpp)
void bindVdbTestHelpers(pybind11::module_& m);  ///< VDB files for tests (vdbTestHelpers.cpp)
void bindGltf(pybind11::module_& m);            ///< the glTF translator (gltfBindings.cpp)
void bindTranslate(pybind11::module_& m);       ///< the USD translation layer (translateBindings.cpp)
void bindVdbGuard(pybind11::module_& m);        ///< the VDB reader guard (vdbGuardBindings.cpp)

/// The core hands out shared_ptr<const T>; pybind11 holds shared_ptr<T>.
template <class T>
std::shared_ptr<T> mutableCopy(const std::shared_ptr<const T>& p) {
    return std::const_pointer_cast<T>(p);
}

/// Pixels (row 0 at the top) as a float32 array: (height, width) for one channel, else
/// (height, width, channels).
inline pybind11::array_t<float> imageArray(const std::vector<float>& data, int width, int height, int channels) {
    using Index = pybind11::ssize_t;
    std::vector<Index> shape = channels == 1 ? std::vector<Index>{height, width} : std::vector<Index>{height, width, channels};
    pybind11::array_t<float> a(shape);
    std::copy(data.begin(), data.end(), a.mutable_data());
    return a;
}

/// An (N, 3) array of numbers (or None: empty) as points; errors name `what`.
inline std::vector<Vec3> arrayToVec3s(const pybind11::object& o, const char* what) {
    namespace py = pybind11;
    if (o.is_none()) return {};
    auto a = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(o);
    if (!a) throw py::type_error(std::string(what) + ": expected an (N, 3) array of numbers");
    if (a.size() == 0) return {};
    if (a.ndim() != 2 || a.shape(1) != 3) throw py::value_error(std::string(what) + ": expected shape (N, 3)");
    auto r = a.unchecked<2>();
    std::vector<Vec3> v(static_cast<size_t>(a.shape(0)));
    for (py::ssize_t i = 0; i < a.shape(0); ++i) v[i] = Vec3(r(i, 0), r(i, 1), r(i, 2));
    return v;
}

}  // namespace volphoton::bindings
