// _core.write_test_vdb: small VDB files with grids of chosen names and value types, for the front
// end's bad-input tests (a grid of the wrong type, a missing grid name) and for TDs reproducing
// problems. Not used by the renderer.
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <openvdb/openvdb.h>

#include <map>
#include <stdexcept>
#include <string>

#include "bindings.h"

namespace py = pybind11;

namespace volphoton::bindings {
namespace {

template <class GridT>
openvdb::GridBase::Ptr makeBall(const std::string& name, int n, typename GridT::ValueType inside, double voxelSize) {
    auto grid = GridT::create();
    grid->setName(name);
    grid->setTransform(openvdb::math::Transform::createLinearTransform(voxelSize));
    auto acc = grid->getAccessor();
    double c = 0.5 * (n - 1), r = 0.45 * n;
    for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j)
            for (int k = 0; k < n; ++k)
                if ((i - c) * (i - c) + (j - c) * (j - c) + (k - c) * (k - c) <= r * r)
                    acc.setValue(openvdb::Coord(i, j, k), inside);
    return grid;
}

void writeTestVdb(const std::string& path, const std::map<std::string, std::string>& grids, int resolution,
                  double voxelSize, double value) {
    if (resolution < 1 || resolution > 256) throw std::invalid_argument("write_test_vdb: resolution must be in [1, 256]");
    if (!(voxelSize > 0)) throw std::invalid_argument("write_test_vdb: voxel_size must be > 0");
    openvdb::initialize();
    openvdb::GridPtrVec out;
    for (const auto& [name, type] : grids) {
        if (type == "float")
            out.push_back(makeBall<openvdb::FloatGrid>(name, resolution, static_cast<float>(value), voxelSize));
        else if (type == "double")
            out.push_back(makeBall<openvdb::DoubleGrid>(name, resolution, value, voxelSize));
        else if (type == "int32")
            out.push_back(makeBall<openvdb::Int32Grid>(name, resolution, static_cast<int32_t>(value), voxelSize));
        else if (type == "vec3s")
            out.push_back(makeBall<openvdb::Vec3SGrid>(name, resolution, openvdb::Vec3s(static_cast<float>(value)), voxelSize));
        else if (type == "bool")
            out.push_back(makeBall<openvdb::BoolGrid>(name, resolution, true, voxelSize));
        else
            throw std::invalid_argument("write_test_vdb: unknown grid type '" + type + "' (float, double, int32, vec3s, bool)");
    }
    try {
        openvdb::io::File file(path);
        file.write(out);
        file.close();
    } catch (const std::exception& e) {
        throw std::runtime_error("cannot write VDB file '" + path + "': " + e.what());
    }
}

}  // namespace

void bindVdbTestHelpers(py::module_& m) {
    m.def("write_test_vdb", [](const std::string& path, const std::map<std::string, std::string>& grids, int resolution,
                               double voxelSize, double value) {
        py::gil_scoped_release release;
        writeTestVdb(path, grids, resolution, voxelSize, value);
    }, py::arg("path"), py::arg("grids"), py::arg("resolution") = 8, py::arg("voxel_size") = 0.125, py::arg("value") = 1.0,
          "Writes a ball of `value` in each grid {name: 'float'|'double'|'int32'|'vec3s'|'bool'} (tests).");
}

}  // namespace volphoton::bindings
