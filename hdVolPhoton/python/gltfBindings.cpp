// volphoton._core.gltf_to_usda: the glTF translator (hdVolPhoton/gltf) for `volphoton gltf2usd`.
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "bindings.h"
#include "gltf/gltfToUsda.h"

namespace py = pybind11;

namespace volphoton::bindings {

void bindGltf(py::module_& m) {
    m.def("gltf_to_usda", [](const std::string& path, const std::string& rootName) {
        gltf::Translation t;
        {
            py::gil_scoped_release release;
            t = gltf::translateFile(path, {rootName});
        }
        py::list diagnostics;
        for (const gltf::Diagnostic& d : t.diagnostics)
            diagnostics.append(py::make_tuple(d.severity == gltf::Severity::Error ? "error" : "warning", d.element, d.message));
        py::dict stats;
        stats["triangles"] = t.triangles;
        stats["mesh_prims"] = t.meshPrims;
        stats["node_prims"] = t.nodePrims;
        return py::make_tuple(t.ok, py::bytes(t.usda), diagnostics, stats);
    }, py::arg("path"), py::arg("root_name") = "",
          "Translates a .gltf/.glb file: (ok, usda text as bytes, [(severity, element, message)], stats). "
          "ok is False when the file could not be read at all.");
}

}  // namespace volphoton::bindings
