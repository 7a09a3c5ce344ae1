// volphoton._core: phase functions, media (homogeneous, exponential, grid), VDB file helpers,
// blackbody colours and the subsurface presets.
#include "bindings.h"
#include "core/blackbody.h"
#include "core/exponentialMedium.h"
#include "core/gridMedium.h"
#include "core/homogeneousMedium.h"
#include "core/phase.h"
#include "core/presets.h"
#include "core/proceduralCloud.h"

namespace py = pybind11;

namespace volphoton::bindings {
namespace {

py::object boundsToPy(const Bounds3& b) {
    if (b.empty()) return py::make_tuple(py::none(), py::none());
    bool finite = isFinite(b.lo) && isFinite(b.hi);
    if (!finite && std::isinf(b.lo.x) && std::isinf(b.hi.x) && b.lo.x < 0 && b.hi.x > 0 && std::isinf(b.lo.y) &&
        std::isinf(b.lo.z) && std::isinf(b.hi.y) && std::isinf(b.hi.z))
        return py::none();
    return py::make_tuple(py::cast(b.lo), py::cast(b.hi));
}

Bounds3 boundsFromPy(const py::object& o) {
    if (o.is_none()) return infiniteBounds();
    auto t = o.cast<std::pair<Vec3, Vec3>>();
    Bounds3 b;
    b.lo = t.first;
    b.hi = t.second;
    if (b.empty()) throw py::value_error("bounds: lo must be <= hi on every axis");
    return b;
}

}  // namespace

void bindMedia(py::module_& m) {
    // ---- phase functions ----------------------------------------------------------------------
    py::class_<PhaseFunction, std::shared_ptr<PhaseFunction>>(m, "PhaseFunction")
        .def("eval", py::overload_cast<double>(&PhaseFunction::eval, py::const_), py::arg("cos_theta"),
             "p(cosTheta) in 1/sr")
        .def("pdf", py::overload_cast<double>(&PhaseFunction::pdf, py::const_), py::arg("cos_theta"))
        .def("sample_cos_theta", &PhaseFunction::sampleCosTheta, py::arg("u"))
        .def("mean_cosine", &PhaseFunction::meanCosine)
        .def("describe", &PhaseFunction::describe)
        .def("__repr__", [](const PhaseFunction& p) { return "<PhaseFunction " + p.describe() + ">"; });
    m.def("isotropic_phase", [] { return mutableCopy(makeIsotropicPhase()); });
    m.def("linear_phase", [](double x) { return mutableCopy(makeLinearPhase(x)); }, py::arg("x"));
    m.def("rayleigh_phase", [] { return mutableCopy(makeRayleighPhase()); });
    m.def("lambertian_sphere_phase", [] { return mutableCopy(makeLambertianSpherePhase()); });
    m.def("henyey_greenstein_phase", [](double g) { return mutableCopy(makeHenyeyGreensteinPhase(g)); }, py::arg("g"));
    m.def("schlick_phase", [](double k) { return mutableCopy(makeSchlickPhase(k)); }, py::arg("k"));
    m.def("schlick_k_from_g", &schlickKFromG, py::arg("g"));
    m.def("tabulated_phase", [](const std::vector<double>& v) { return mutableCopy(makeTabulatedPhase(v)); },
          py::arg("values"));
    m.def("mixture_phase", [](const std::vector<std::pair<double, std::shared_ptr<PhaseFunction>>>& lobes) {
        std::vector<std::pair<double, PhasePtr>> l;
        for (auto& [w, p] : lobes) {
            if (!p) throw py::value_error("mixture_phase: a lobe is None");
            l.emplace_back(w, p);
        }
        return mutableCopy(makeMixturePhase(l));
    }, py::arg("lobes"), "lobes: [(weight, PhaseFunction), ...]");

    // ---- media --------------------------------------------------------------------------------
    py::class_<MediumCoefficients>(m, "MediumCoefficients")
        .def(py::init<>())
        .def_readwrite("sigma_a", &MediumCoefficients::sigma_a)
        .def_readwrite("sigma_s", &MediumCoefficients::sigma_s)
        .def_readwrite("emission", &MediumCoefficients::emission)
        .def_property("phase", [](const MediumCoefficients& c) { return mutableCopy(c.phase); },
                      [](MediumCoefficients& c, std::shared_ptr<PhaseFunction> p) { c.phase = p; })
        .def_property_readonly("sigma_t", &MediumCoefficients::sigma_t)
        .def("max_albedo", &MediumCoefficients::maxAlbedo)
        .def_static("from_albedo", [](double density, const Spectrum& ext, const Spectrum& albedo, const Spectrum& emission,
                                      std::shared_ptr<PhaseFunction> phase) {
            return MediumCoefficients::fromAlbedo(density, ext, albedo, emission, phase);
        }, py::arg("density"), py::arg("extinction_color"), py::arg("albedo"), py::arg("emission") = Spectrum(0.0),
           py::arg("phase") = nullptr,
           "sigma_t = density * extinction_color, sigma_s = albedo * sigma_t (the schema's parametrisation)")
        .def("__repr__", [](const MediumCoefficients& c) {
            return py::str("MediumCoefficients(sigma_a={}, sigma_s={}, emission={})")
                .format(py::cast(c.sigma_a), py::cast(c.sigma_s), py::cast(c.emission)).cast<std::string>();
        });
    m.attr("MediumCoefficients").attr("fromAlbedo") = m.attr("MediumCoefficients").attr("from_albedo");

    py::class_<Medium, std::shared_ptr<Medium>>(m, "Medium")
        .def("properties", [](const Medium& med, const Vec3& p) {
            MediumProperties mp = med.properties(p);
            py::dict d;
            d["sigma_a"] = mp.sigma_a;
            d["sigma_s"] = mp.sigma_s;
            d["sigma_t"] = mp.sigma_t();
            d["emission"] = mp.emission;
            d["lobes"] = mp.lobeCount;
            return d;
        }, py::arg("p"), "Coefficients at a world point: dict sigma_a, sigma_s, sigma_t, emission, lobes")
        .def("optical_depth", [](const Medium& med, const Vec3& o, const Vec3& d, double t0, double t1) -> py::object {
            auto tau = med.opticalDepth(Ray{o, normalize(d)}, t0, t1);
            if (!tau) return py::none();
            return py::cast(*tau);
        }, py::arg("origin"), py::arg("direction"), py::arg("t0"), py::arg("t1"),
           "Closed-form optical depth per channel, or None where the medium has none")
        .def("bounds", [](const Medium& med) { return boundsToPy(med.bounds()); },
             "((lo), (hi)) world box, or None when unbounded")
        .def("is_emissive", &Medium::isEmissive)
        .def("max_albedo", &Medium::maxAlbedo)
        .def("describe", &Medium::describe)
        .def("__repr__", [](const Medium& med) { return "<Medium " + med.describe() + ">"; });

    py::class_<HomogeneousMedium, Medium, std::shared_ptr<HomogeneousMedium>>(m, "HomogeneousMedium")
        .def(py::init([](const MediumCoefficients& c, const py::object& bounds) {
            return std::make_shared<HomogeneousMedium>(c, boundsFromPy(bounds));
        }), py::arg("coefficients"), py::arg("bounds") = py::none());

    py::class_<ExponentialMedium, Medium, std::shared_ptr<ExponentialMedium>>(m, "ExponentialMedium")
        .def(py::init([](const MediumCoefficients& c, double a, double b, const Vec3& origin, const Vec3& up,
                         const py::object& bounds) {
            return std::make_shared<ExponentialMedium>(c, a, b, origin, up, boundsFromPy(bounds));
        }), py::arg("coefficients"), py::arg("a") = 1.0, py::arg("b") = 1.0, py::arg("origin") = Vec3(0, 0, 0),
           py::arg("up") = Vec3(0, 1, 0), py::arg("bounds") = py::none())
        .def("relative_density", &ExponentialMedium::relativeDensity, py::arg("p"));

    py::class_<GridMediumDesc>(m, "GridMediumDesc")
        .def(py::init<>())
        .def_readwrite("file_path", &GridMediumDesc::filePath)
        .def_readwrite("density_grid", &GridMediumDesc::densityGrid)
        .def_readwrite("temperature_grid", &GridMediumDesc::temperatureGrid)
        .def_readwrite("emission_grid", &GridMediumDesc::emissionGrid)
        .def_readwrite("albedo_grid", &GridMediumDesc::albedoGrid)
        .def_readwrite("density_scale", &GridMediumDesc::densityScale)
        .def_readwrite("max_active_voxels", &GridMediumDesc::maxActiveVoxels)
        .def_readwrite("extinction_color", &GridMediumDesc::extinctionColor)
        .def_readwrite("albedo", &GridMediumDesc::albedo)
        .def_readwrite("emission", &GridMediumDesc::emission)
        .def_readwrite("emission_scale", &GridMediumDesc::emissionScale)
        .def_readwrite("temperature_scale", &GridMediumDesc::temperatureScale)
        .def_property("phase", [](const GridMediumDesc& d) { return mutableCopy(d.phase); },
                      [](GridMediumDesc& d, std::shared_ptr<PhaseFunction> p) { d.phase = p; })
        .def_readwrite("object_to_world", &GridMediumDesc::objectToWorld);

    py::class_<GridMedium, Medium, std::shared_ptr<GridMedium>>(m, "GridMedium")
        .def("max_density", &GridMedium::maxDensity)
        .def("index_bounds", [](const GridMedium& g) { return boundsToPy(g.indexBounds()); })
        .def("active_voxel_count", &GridMedium::activeVoxelCount)
        .def("density", &GridMedium::density, py::arg("p"))
        .def("majorant_build_seconds", &GridMedium::majorantBuildSeconds)
        .def_property_readonly("world_to_index", &GridMedium::worldToIndex)
        .def_property_readonly("index_to_world", &GridMedium::indexToWorld);
    m.attr("DEFAULT_MAX_GRID_VOXELS") = GridMediumDesc::kDefaultMaxGridVoxels;
    m.def("subsurface_presets", [] {
        py::list out;
        for (const SubsurfacePreset& p : subsurfacePresets())
            out.append(py::make_tuple(p.name, py::make_tuple(p.sigmaSPrime[0], p.sigmaSPrime[1], p.sigmaSPrime[2]),
                                      py::make_tuple(p.sigmaA[0], p.sigmaA[1], p.sigmaA[2])));
        return out;
    }, "[(name, sigma_s' RGB, sigma_a RGB)] in 1/mm (Jensen et al. 2001, table 2; core/presets.h)");
    m.def("load_grid_medium", [](const GridMediumDesc& desc) {
        GridMediumDesc copy = desc;
        py::gil_scoped_release release;
        return loadGridMedium(copy);
    }, py::arg("desc"),
          "Opens desc.file_path and builds the medium; RuntimeError naming the file and grid on failure.");
    m.def("write_procedural_cloud_vdb", [](const std::string& path, int resolution, double voxelSize, uint64_t seed,
                                           const std::string& shape) {
        CloudShape s;
        if (shape == "blob") s = CloudShape::Blob;
        else if (shape == "cumulus") s = CloudShape::Cumulus;
        else throw py::value_error("write_procedural_cloud_vdb: shape must be 'blob' or 'cumulus', not '" + shape + "'");
        py::gil_scoped_release release;
        writeProceduralCloudVdb(path, resolution, voxelSize, seed, s);
    }, py::arg("path"), py::arg("resolution") = 64, py::arg("voxel_size") = 1.0 / 64, py::arg("seed") = 1,
          py::arg("shape") = "blob",
          "Deterministic procedural cloud FloatGrid 'density' (see proceduralCloud.h): shape 'blob' (tests, "
          "benchmark) or 'cumulus' (the example scenes).");
    m.def("blackbody_color", &blackbodyColor, py::arg("kelvin"));
    m.def("blackbody_radiance", &blackbodyRadiance, py::arg("kelvin"));
}

}  // namespace volphoton::bindings
