// volphoton._core: pybind11 bindings of the renderer core for the usd-core front end (volphoton.cli).
//
// Conventions (see converters.h): vectors and colours are 3-tuples (any 3-sequence is accepted, a
// colour also takes one number), transforms are (4, 4) float64 arrays in the core's column-vector
// convention, bounds are ((lo), (hi)) tuples or None for "infinite", images are numpy float32 arrays
// (H, W, 3) or (H, W) with row 0 at the top. C++ std::invalid_argument -> ValueError,
// std::runtime_error -> RuntimeError (message unchanged).
//
// Threads: every call that may run TBB work (Scene, Renderer, render, render_pass, load_grid_medium,
// GridMedium statistics aside) releases the GIL. Python callbacks (progress, cancel, the diagnostic
// sink) re-acquire it; an exception raised in one cancels the render and is re-raised by render().
// Ctrl-C (SIGINT) is polled from the main thread during render() and cancels it with
// KeyboardInterrupt.
#include <pybind11/functional.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <atomic>
#include <memory>
#include <mutex>
#include <thread>

#include "converters.h"
#include "core/camera.h"
#include "core/diagnostics.h"
#include "core/exponentialMedium.h"
#include "core/gridMedium.h"
#include "core/homogeneousMedium.h"
#include "core/integrator.h"
#include "core/lights.h"
#include "core/phase.h"
#include "core/presets.h"
#include "core/previewSurface.h"
#include "core/scene.h"

namespace py = pybind11;
using namespace volphoton;

namespace {

template <class T>
std::shared_ptr<T> mutableCopy(const std::shared_ptr<const T>& p) {
    return std::const_pointer_cast<T>(p);
}

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

py::array_t<double> vec3sToArray(const std::vector<Vec3>& v) {
    py::array_t<double> a({static_cast<py::ssize_t>(v.size()), static_cast<py::ssize_t>(3)});
    auto w = a.mutable_unchecked<2>();
    for (size_t i = 0; i < v.size(); ++i) {
        w(i, 0) = v[i].x;
        w(i, 1) = v[i].y;
        w(i, 2) = v[i].z;
    }
    return a;
}

std::vector<Vec3> arrayToVec3s(const py::object& o, const char* what) {
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

py::array_t<float> imageArray(const std::vector<float>& data, int width, int height, int channels) {
    std::vector<py::ssize_t> shape = channels == 1 ? std::vector<py::ssize_t>{height, width}
                                                   : std::vector<py::ssize_t>{height, width, channels};
    py::array_t<float> a(shape);
    std::copy(data.begin(), data.end(), a.mutable_data());
    return a;
}

const char* severityName(Severity s) {
    return s == Severity::Error ? "error" : s == Severity::Warning ? "warning" : "info";
}

const char* integratorName(RenderSettings::Integrator i) {
    return i == RenderSettings::Integrator::PhotonMap ? "photonMap" : "pathTracer";
}

py::dict statsToDict(const RenderStats& s) {
    py::dict d;
    d["passes"] = s.passes;
    d["camera_samples"] = s.cameraSamples;
    d["photons_traced"] = s.photonsTraced;
    d["photons_stored"] = s.photonsStored;
    d["seconds"] = s.seconds;
    d["photon_seconds"] = s.photonSeconds;
    d["camera_seconds"] = s.cameraSeconds;
    d["photon_radius"] = s.photonRadius;
    d["multiple_to_single_ratio"] = s.multipleToSingleRatio;
    d["photon_map_bytes"] = s.photonMapBytes;
    d["photons_thinned"] = s.photonsThinned;
    d["photons_radius_capped"] = s.photonsRadiusCapped;
    d["passes_run"] = s.passesRun;
    d["passes_skipped"] = s.passesSkipped;
    d["cancelled"] = s.cancelled;
    return d;
}

py::dict settingsToDict(const RenderSettings& s) {
    py::dict d;
    d["integrator"] = integratorName(s.integrator);
    d["width"] = s.width;
    d["height"] = s.height;
    d["samplesPerPixel"] = s.samplesPerPixel;
    d["maxDepth"] = s.maxDepth;
    d["rouletteDepth"] = s.rouletteDepth;
    d["seed"] = s.seed;
    d["threads"] = s.threads;
    d["photonsPerPass"] = s.photonsPerPass;
    d["initialRadius"] = s.initialRadius;
    d["radiusAlpha"] = s.radiusAlpha;
    d["photonRadiusMfp"] = s.photonRadiusMfp;
    d["stratifiedDims"] = s.stratifiedDims;
    d["marchStep"] = s.marchStep;
    d["singleScattering"] = s.singleScattering;
    d["multipleScattering"] = s.multipleScattering;
    d["multipleThreshold"] = s.multipleThreshold;
    d["transmittanceCutoff"] = s.transmittanceCutoff;
    d["photonMapBudgetBytes"] = s.photonMapBudgetBytes;
    d["domeVisibleToCamera"] = s.domeVisibleToCamera;
    return d;
}

/// State shared by the progress/cancel wrappers of one render() call. Python objects are borrowed
/// (the caller's frame keeps them alive), so copying the std::functions never touches refcounts.
struct CallbackState {
    py::handle progress, cancel;
    std::thread::id mainThread = std::this_thread::get_id();
    std::atomic<bool> failed{false};
    std::mutex mutex;
    std::unique_ptr<py::error_already_set> error;  // only touched with the GIL held

    void fail(py::error_already_set& e) {
        std::lock_guard<std::mutex> lock(mutex);
        if (!error) error = std::make_unique<py::error_already_set>(std::move(e));
        failed = true;
    }
    /// Polls Ctrl-C (main thread only) and the Python cancel callable; true = stop.
    bool shouldCancel() {
        if (failed.load(std::memory_order_relaxed)) return true;
        bool onMain = std::this_thread::get_id() == mainThread;
        if (!onMain && !cancel) return false;
        py::gil_scoped_acquire gil;
        try {
            if (onMain && PyErr_CheckSignals() != 0) throw py::error_already_set();
            if (cancel) {
                py::object r = cancel();
                int truth = PyObject_IsTrue(r.ptr());
                if (truth < 0) throw py::error_already_set();
                return truth != 0;
            }
        } catch (py::error_already_set& e) {
            fail(e);
            return true;
        }
        return false;
    }
    void reportProgress(int done, int total) {
        if (failed.load(std::memory_order_relaxed)) return;
        py::gil_scoped_acquire gil;
        try {
            if (PyErr_CheckSignals() != 0) throw py::error_already_set();
            if (progress) progress(done, total);
        } catch (py::error_already_set& e) {
            fail(e);
        }
    }
    /// Re-raises a stored Python exception (GIL held).
    void rethrow() {
        if (error) {
            py::error_already_set e = *error;
            error.reset();
            throw e;
        }
    }
};

py::handle callableOrNull(const py::object& o, const char* what) {
    if (o.is_none()) return py::handle();
    if (!PyCallable_Check(o.ptr())) throw py::type_error(std::string(what) + " must be callable or None");
    return o;
}

/// Holder for the Python diagnostic sink; never destroyed after the interpreter is gone.
struct PySink {
    py::object fn;
};

void installSink(const py::object& fn) {
    if (fn.is_none()) {
        setDiagnosticSink({});
        return;
    }
    if (!PyCallable_Check(fn.ptr())) throw py::type_error("set_diagnostic_sink: expected a callable(severity, message) or None");
    std::shared_ptr<PySink> holder(new PySink{fn}, [](PySink* p) {
        if (Py_IsInitialized()) {
            py::gil_scoped_acquire gil;
            delete p;
        }  // else: leaked on purpose (no interpreter to decref with)
    });
    setDiagnosticSink([holder](Severity s, const std::string& message) {
        if (!Py_IsInitialized()) return;
        py::gil_scoped_acquire gil;
        try {
            holder->fn(severityName(s), message);
        } catch (py::error_already_set& e) {
            e.discard_as_unraisable("volphoton diagnostic sink");
        }
    });
}

}  // namespace

PYBIND11_MODULE(_core, m) {
    m.doc() = "volphoton renderer core (C++), for the usd-core front end. See volphoton/__init__.py.";
#ifdef VOLPHOTON_VERSION
    m.attr("__version__") = VOLPHOTON_VERSION;
#endif
#ifdef VOLPHOTON_NO_VOLUMES
    m.attr("NO_VOLUMES") = true;
#else
    m.attr("NO_VOLUMES") = false;
#endif

    // ---- diagnostics --------------------------------------------------------------------------
    m.def("set_diagnostic_sink", &installSink, py::arg("sink"),
          "Routes core warnings to sink(severity: str, message: str) ('info', 'warning', 'error'); None "
          "restores the default (stderr). The sink may be called from render threads (it holds the GIL).");
    m.def("report", [](const std::string& severity, const std::string& message) {
        Severity s = severity == "error" ? Severity::Error : severity == "info" ? Severity::Info : Severity::Warning;
        report(s, message);
    }, py::arg("severity"), py::arg("message"), "Sends a message through the installed sink (tests).");
    // Drop the Python sink before the interpreter shuts down.
    py::module_::import("atexit").attr("register")(py::cpp_function([]() { setDiagnosticSink({}); }));

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
    m.def("preview_surface_material", [](std::tuple<double, double, double> diffuse, std::tuple<double, double, double> emissive,
                                         double opacity, double opacityThreshold, double ior, bool iorAuthored, double metallic) {
        PreviewSurfaceInputs in;
        in.diffuseColor = Spectrum(std::get<0>(diffuse), std::get<1>(diffuse), std::get<2>(diffuse));
        in.emissiveColor = Spectrum(std::get<0>(emissive), std::get<1>(emissive), std::get<2>(emissive));
        in.opacity = opacity;
        in.opacityThreshold = opacityThreshold;
        in.ior = ior;
        in.iorAuthored = iorAuthored;
        in.metallic = metallic;
        std::vector<PreviewSurfaceNote> notes;
        std::optional<SurfaceMaterial> m = previewSurfaceMaterial(in, &notes);
        py::list out;
        for (const PreviewSurfaceNote& n : notes) out.append(py::make_tuple(n.error ? "error" : "warning", n.input, n.message));
        return py::make_tuple(m ? py::cast(*m) : py::none(), out);
    }, py::arg("diffuse"), py::arg("emissive"), py::arg("opacity"), py::arg("opacity_threshold"), py::arg("ior"),
       py::arg("ior_authored"), py::arg("metallic"),
       "(SurfaceMaterial or None = not rendered, [(severity, input, message)]): core/previewSurface.h's rules");
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
    m.def("write_procedural_cloud_vdb", [](const std::string& path, int resolution, double voxelSize, uint64_t seed) {
        py::gil_scoped_release release;
        writeProceduralCloudVdb(path, resolution, voxelSize, seed);
    }, py::arg("path"), py::arg("resolution") = 64, py::arg("voxel_size") = 1.0 / 64, py::arg("seed") = 1,
          "Deterministic procedural cloud FloatGrid 'density' (see gridMedium.h).");
    m.def("blackbody_color", &blackbodyColor, py::arg("kelvin"));
    m.def("blackbody_radiance", &blackbodyRadiance, py::arg("kelvin"));

    // ---- lights -------------------------------------------------------------------------------
    py::class_<Light, std::shared_ptr<Light>>(m, "Light")
        .def("power", &Light::power, py::arg("scene_radius") = 1.0, "Emitted power (W); scene radius for distant/dome")
        .def("is_delta", &Light::isDelta)
        .def("describe", &Light::describe)
        .def("sample", [](const Light& l, const Vec3& ref, double u1, double u2) {
            LightSample s = l.sample(ref, u1, u2);
            py::dict d;
            d["wi"] = s.wi;
            d["dist"] = s.dist;
            d["Li"] = s.Li;
            d["pdf"] = s.pdf;
            d["is_delta"] = s.isDelta;
            return d;
        }, py::arg("ref"), py::arg("u1") = 0.5, py::arg("u2") = 0.5)
        .def("intersect", [](const Light& l, const Vec3& o, const Vec3& d) -> py::object {
            double t, pdf;
            Spectrum Le;
            if (!l.intersect(Ray{o, normalize(d)}, Infinity, &t, &Le, &pdf)) return py::none();
            return py::make_tuple(t, py::cast(Le), pdf);
        }, py::arg("origin"), py::arg("direction"), "(t, radiance, pdf) of a ray hitting the light, or None")
        .def("__repr__", [](const Light& l) { return "<Light " + l.describe() + ">"; });

    py::class_<LatLongImage>(m, "LatLongImage")
        .def(py::init<>())
        .def(py::init([](py::array_t<float, py::array::c_style | py::array::forcecast> rgb) {
            if (rgb.ndim() != 3 || rgb.shape(2) != 3) throw py::value_error("LatLongImage: expected an (H, W, 3) array");
            LatLongImage img;
            img.height = static_cast<int>(rgb.shape(0));
            img.width = static_cast<int>(rgb.shape(1));
            img.rgb.assign(rgb.data(), rgb.data() + rgb.size());
            return img;
        }), py::arg("rgb"))
        .def_readonly("width", &LatLongImage::width)
        .def_readonly("height", &LatLongImage::height)
        .def_property_readonly("rgb", [](const LatLongImage& i) { return imageArray(i.rgb, i.width, i.height, 3); });
    m.def("load_lat_long_exr", [](const std::string& path) {
        py::gil_scoped_release release;
        return loadLatLongExr(path);
    }, py::arg("path"));
    m.def("distant_light", [](const Vec3& dir, double halfAngle, const Spectrum& E) {
        return mutableCopy(makeDistantLight(dir, halfAngle, E));
    }, py::arg("direction"), py::arg("half_angle"), py::arg("irradiance"),
          "direction: propagation direction; half_angle in radians; irradiance normal to the direction");
    m.def("sphere_light", [](const Vec3& p, double r, const Spectrum& L) { return mutableCopy(makeSphereLight(p, r, L)); },
          py::arg("position"), py::arg("radius"), py::arg("radiance"),
          "radius 0: point light and `radiance` is the intensity (W/sr)");
    m.def("spot_light", [](const Vec3& p, double r, const Spectrum& L, const Vec3& axis, double cone, double softness) {
        return mutableCopy(makeSpotLight(p, r, L, axis, cone, softness));
    }, py::arg("position"), py::arg("radius"), py::arg("radiance"), py::arg("axis"), py::arg("cone_angle"),
          py::arg("cone_softness") = 0.0);
    m.def("rect_light", [](const Affine& toWorld, double w, double h, const Spectrum& L) {
        return mutableCopy(makeRectLight(toWorld, w, h, L));
    }, py::arg("light_to_world"), py::arg("width"), py::arg("height"), py::arg("radiance"));
    m.def("disk_light", [](const Affine& toWorld, double r, const Spectrum& L) {
        return mutableCopy(makeDiskLight(toWorld, r, L));
    }, py::arg("light_to_world"), py::arg("radius"), py::arg("radiance"));
    m.def("dome_light", [](const Spectrum& L, const py::object& image, const py::object& toWorld) {
        LatLongImage img = image.is_none() ? LatLongImage() : image.cast<LatLongImage>();
        Affine m4 = toWorld.is_none() ? Affine() : toWorld.cast<Affine>();
        py::gil_scoped_release release;
        return mutableCopy(makeDomeLight(L, std::move(img), m4));
    }, py::arg("radiance"), py::arg("image") = py::none(), py::arg("light_to_world") = py::none());
    m.def("spot_falloff", &spotFalloff, py::arg("cos_angle"), py::arg("cone_angle"), py::arg("cone_softness"));

    // ---- camera -------------------------------------------------------------------------------
    py::class_<CameraDesc> cam(m, "CameraDesc");
    py::enum_<CameraDesc::Projection>(cam, "Projection")
        .value("Perspective", CameraDesc::Projection::Perspective)
        .value("Orthographic", CameraDesc::Projection::Orthographic);
    cam.def(py::init<>())
        .def_readwrite("camera_to_world", &CameraDesc::cameraToWorld)
        .def_readwrite("projection", &CameraDesc::projection)
        .def_readwrite("tan_half_fov_x", &CameraDesc::tanHalfFovX)
        .def_readwrite("ortho_width", &CameraDesc::orthoWidth)
        .def_readwrite("lens_radius", &CameraDesc::lensRadius)
        .def_readwrite("focus_distance", &CameraDesc::focusDistance)
        .def_readwrite("near_clip", &CameraDesc::nearClip)
        .def_readwrite("far_clip", &CameraDesc::farClip);
    py::class_<Camera>(m, "Camera")
        .def(py::init<const CameraDesc&, int, int>(), py::arg("desc"), py::arg("width"), py::arg("height"))
        .def("generate_ray", [](const Camera& c, double px, double py_, double u1, double u2) {
            double t0, t1;
            Ray r = c.generateRay(px, py_, u1, u2, &t0, &t1);
            return py::make_tuple(py::cast(r.o), py::cast(r.d), t0, t1);
        }, py::arg("px"), py::arg("py"), py::arg("u1") = 0.5, py::arg("u2") = 0.5,
           "(origin, direction, t_min, t_max) through image position (px, py) in pixels, (0, 0) top-left")
        .def("position", &Camera::position);

    // ---- scene --------------------------------------------------------------------------------
    py::class_<SurfaceMaterial> mat(m, "SurfaceMaterial");
    py::enum_<SurfaceMaterial::Kind>(mat, "Kind")
        .value("Lambertian", SurfaceMaterial::Kind::Lambertian)
        .value("Dielectric", SurfaceMaterial::Kind::Dielectric)
        .value("Boundary", SurfaceMaterial::Kind::Boundary);
    mat.def(py::init<>())
        .def(py::init([](SurfaceMaterial::Kind kind, const Spectrum& albedo, const Spectrum& emission, double ior) {
            SurfaceMaterial s;
            s.kind = kind;
            s.albedo = albedo;
            s.emission = emission;
            s.ior = ior;
            return s;
        }), py::arg("kind") = SurfaceMaterial::Kind::Lambertian, py::arg("albedo") = Spectrum(0.5),
           py::arg("emission") = Spectrum(0.0), py::arg("ior") = 1.5)
        .def_readwrite("kind", &SurfaceMaterial::kind)
        .def_readwrite("albedo", &SurfaceMaterial::albedo)
        .def_readwrite("emission", &SurfaceMaterial::emission)
        .def_readwrite("ior", &SurfaceMaterial::ior)
        .def("__repr__", [](const SurfaceMaterial& s) {
            return py::str("SurfaceMaterial({}, albedo={}, emission={}, ior={})")
                .format(py::cast(s.kind), py::cast(s.albedo), py::cast(s.emission), s.ior).cast<std::string>();
        });

    py::class_<MeshDesc>(m, "MeshDesc")
        .def(py::init<>())
        .def_readwrite("name", &MeshDesc::name)
        .def_property("points", [](const MeshDesc& d) { return vec3sToArray(d.points); },
                      [](MeshDesc& d, const py::object& a) { d.points = arrayToVec3s(a, "MeshDesc.points"); },
                      "(N, 3) float64 object-space points")
        .def_property("normals", [](const MeshDesc& d) { return vec3sToArray(d.normals); },
                      [](MeshDesc& d, const py::object& a) { d.normals = arrayToVec3s(a, "MeshDesc.normals"); },
                      "(N, 3) per-vertex normals, or empty")
        .def_property("indices", [](const MeshDesc& d) {
            py::array_t<uint32_t> a(static_cast<py::ssize_t>(d.indices.size()));
            std::copy(d.indices.begin(), d.indices.end(), a.mutable_data());
            return a;
        }, [](MeshDesc& d, const py::object& o) {
            auto a = py::array_t<int64_t, py::array::c_style | py::array::forcecast>::ensure(o);
            if (!a) throw py::type_error("MeshDesc.indices: expected an integer array");
            const int64_t* p = a.data();
            d.indices.resize(static_cast<size_t>(a.size()));
            for (py::ssize_t i = 0; i < a.size(); ++i) {
                if (p[i] < 0 || p[i] > 0xffffffffLL) throw py::value_error("MeshDesc.indices: index out of range");
                d.indices[i] = static_cast<uint32_t>(p[i]);
            }
        }, "flat triangle vertex indices (3 per triangle; an (M, 3) array is flattened)")
        .def_readwrite("material", &MeshDesc::material)
        .def_readwrite("interior_medium", &MeshDesc::interiorMedium)
        .def_property_readonly("triangle_count", [](const MeshDesc& d) { return d.indices.size() / 3; });

    py::class_<InstanceDesc>(m, "InstanceDesc")
        .def(py::init<>())
        .def(py::init([](int mesh, const Affine& t) { return InstanceDesc{mesh, t}; }), py::arg("mesh"),
             py::arg("transform"))
        .def_readwrite("mesh", &InstanceDesc::mesh)
        .def_readwrite("transform", &InstanceDesc::transform);

    py::class_<SceneDesc>(m, "SceneDesc")
        .def(py::init<>())
        .def_readwrite("meshes", &SceneDesc::meshes, "list of MeshDesc (a copy: use add_mesh to append)")
        .def_readwrite("instances", &SceneDesc::instances)
        .def_property("media", [](const SceneDesc& d) {
            std::vector<std::shared_ptr<Medium>> v;
            for (auto& p : d.media) v.push_back(mutableCopy(p));
            return v;
        }, [](SceneDesc& d, const std::vector<std::shared_ptr<Medium>>& v) { d.media.assign(v.begin(), v.end()); })
        .def_readwrite("unbounded_media", &SceneDesc::unboundedMedia)
        .def_property("lights", [](const SceneDesc& d) {
            std::vector<std::shared_ptr<Light>> v;
            for (auto& p : d.lights) v.push_back(mutableCopy(p));
            return v;
        }, [](SceneDesc& d, const std::vector<std::shared_ptr<Light>>& v) { d.lights.assign(v.begin(), v.end()); })
        .def_readwrite("camera", &SceneDesc::camera)
        .def("add_mesh", [](SceneDesc& d, const MeshDesc& mesh) {
            d.meshes.push_back(mesh);
            return static_cast<int>(d.meshes.size() - 1);
        }, py::arg("mesh"), "Appends a mesh; returns its index")
        .def("add_instance", [](SceneDesc& d, int mesh, const Affine& t) {
            d.instances.push_back({mesh, t});
            return static_cast<int>(d.instances.size() - 1);
        }, py::arg("mesh"), py::arg("transform"))
        .def("add_medium", [](SceneDesc& d, std::shared_ptr<Medium> med, bool unbounded) {
            if (!med) throw py::value_error("add_medium: medium is None");
            d.media.push_back(med);
            int i = static_cast<int>(d.media.size() - 1);
            if (unbounded) d.unboundedMedia.push_back(i);
            return i;
        }, py::arg("medium"), py::arg("unbounded") = false,
           "Appends a medium; unbounded=True also lists it in unbounded_media (volumes, fog, atmospheres)")
        .def("add_light", [](SceneDesc& d, std::shared_ptr<Light> l) {
            if (!l) throw py::value_error("add_light: light is None");
            d.lights.push_back(l);
            return static_cast<int>(d.lights.size() - 1);
        }, py::arg("light"))
        .def("mesh", [](const SceneDesc& d, int i) {
            if (i < 0 || i >= static_cast<int>(d.meshes.size())) throw py::index_error("mesh index out of range");
            return d.meshes[i];
        }, py::arg("index"))
        .def_property_readonly("mesh_count", [](const SceneDesc& d) { return d.meshes.size(); })
        .def_property_readonly("instance_count", [](const SceneDesc& d) { return d.instances.size(); });

    py::class_<Scene, std::shared_ptr<Scene>>(m, "Scene")
        .def(py::init([](const SceneDesc& desc) {
            SceneDesc copy = desc;
            py::gil_scoped_release release;
            return std::make_shared<Scene>(std::move(copy));
        }), py::arg("desc"), "Builds the BVH (validates the description: ValueError on bad input)")
        .def_property_readonly("center", &Scene::center)
        .def_property_readonly("radius", &Scene::radius)
        .def_property_readonly("has_media", &Scene::hasMedia)
        .def_property_readonly("has_surfaces", &Scene::hasSurfaces)
        .def_property_readonly("has_emissive_media", &Scene::hasEmissiveMedia)
        .def_property_readonly("light_count", [](const Scene& s) { return s.lights().size(); })
        .def("intersect", [](const Scene& s, const Vec3& o, const Vec3& d, double tMax) -> py::object {
            SurfaceHit hit;
            if (!s.intersect(Ray{o, normalize(d)}, 0.0, tMax, &hit)) return py::none();
            py::dict r;
            r["t"] = hit.t;
            r["p"] = hit.p;
            r["ng"] = hit.ng;
            r["ns"] = hit.ns;
            r["mesh"] = hit.mesh;
            r["instance"] = hit.instance;
            return r;
        }, py::arg("origin"), py::arg("direction"), py::arg("t_max") = Infinity);

    // ---- rendering ----------------------------------------------------------------------------
    py::class_<RenderSettings> rs(m, "RenderSettings");
    py::enum_<RenderSettings::Integrator>(rs, "Integrator")
        .value("PathTracer", RenderSettings::Integrator::PathTracer)
        .value("PhotonMap", RenderSettings::Integrator::PhotonMap);
    rs.def(py::init<>())
        .def_readwrite("integrator", &RenderSettings::integrator)
        .def_readwrite("width", &RenderSettings::width)
        .def_readwrite("height", &RenderSettings::height)
        .def_readwrite("samples_per_pixel", &RenderSettings::samplesPerPixel)
        .def_readwrite("max_depth", &RenderSettings::maxDepth)
        .def_readwrite("roulette_depth", &RenderSettings::rouletteDepth)
        .def_readwrite("seed", &RenderSettings::seed)
        .def_readwrite("threads", &RenderSettings::threads)
        .def_readwrite("photons_per_pass", &RenderSettings::photonsPerPass)
        .def_readwrite("initial_radius", &RenderSettings::initialRadius)
        .def_readwrite("radius_alpha", &RenderSettings::radiusAlpha)
        .def_readwrite("photon_radius_mfp", &RenderSettings::photonRadiusMfp)
        .def_readwrite("stratified_dims", &RenderSettings::stratifiedDims)
        .def_readwrite("march_step", &RenderSettings::marchStep)
        .def_readwrite("single_scattering", &RenderSettings::singleScattering)
        .def_readwrite("multiple_scattering", &RenderSettings::multipleScattering)
        .def_readwrite("multiple_threshold", &RenderSettings::multipleThreshold)
        .def_readwrite("transmittance_cutoff", &RenderSettings::transmittanceCutoff)
        .def_readwrite("photon_map_budget_bytes", &RenderSettings::photonMapBudgetBytes)
        .def_readwrite("dome_visible_to_camera", &RenderSettings::domeVisibleToCamera)
        .def_readwrite("max_grid_voxels", &RenderSettings::maxGridVoxels)
        .def("to_dict", &settingsToDict, "Settings under their documented (integrator.h) names")
        .def("__repr__", [](const RenderSettings& s) { return py::repr(settingsToDict(s)).cast<std::string>(); });

    py::class_<Film> film(m, "Film");
    py::enum_<Film::Aov>(film, "Aov")
        .value("Beauty", Film::Beauty)
        .value("Single", Film::Single)
        .value("Multiple", Film::Multiple)
        .value("Emission", Film::Emission)
        .value("Surface", Film::Surface);
    film.def_property_readonly("width", &Film::width)
        .def_property_readonly("height", &Film::height)
        .def("rgb", [](const Film& f, Film::Aov aov) { return imageArray(f.resolveRgb(aov), f.width(), f.height(), 3); },
             py::arg("aov"), "(H, W, 3) float32 mean per pixel")
        .def("alpha", [](const Film& f) { return imageArray(f.resolveAlpha(), f.width(), f.height(), 1); })
        .def("depth", [](const Film& f) { return imageArray(f.resolveDepth(), f.width(), f.height(), 1); },
             "(H, W) float32 camera distance to the first surface, +inf where none")
        .def("samples", [](const Film& f) {
            py::array_t<uint32_t> a({f.height(), f.width()});
            auto w = a.mutable_unchecked<2>();
            for (int y = 0; y < f.height(); ++y)
                for (int x = 0; x < f.width(); ++x) w(y, x) = f.samples(x, y);
            return a;
        })
        .def_property_readonly("beauty", [](const Film& f) { return imageArray(f.resolveRgb(Film::Beauty), f.width(), f.height(), 3); })
        .def_property_readonly("single", [](const Film& f) { return imageArray(f.resolveRgb(Film::Single), f.width(), f.height(), 3); })
        .def_property_readonly("multiple", [](const Film& f) { return imageArray(f.resolveRgb(Film::Multiple), f.width(), f.height(), 3); })
        .def_property_readonly("emission", [](const Film& f) { return imageArray(f.resolveRgb(Film::Emission), f.width(), f.height(), 3); })
        .def_property_readonly("surface", [](const Film& f) { return imageArray(f.resolveRgb(Film::Surface), f.width(), f.height(), 3); });

    py::class_<Renderer, std::shared_ptr<Renderer>>(m, "Renderer")
        .def(py::init([](std::shared_ptr<Scene> scene, const RenderSettings& settings) {
            if (!scene) throw py::value_error("Renderer: scene is None");
            py::gil_scoped_release release;
            return std::make_shared<Renderer>(scene, settings);
        }), py::arg("scene"), py::arg("settings"))
        .def("render", [](Renderer& r, const py::object& progress, const py::object& cancel) {
            CallbackState state;
            state.progress = callableOrNull(progress, "progress");
            state.cancel = callableOrNull(cancel, "cancel");
            CallbackState* sp = &state;
            ProgressCallback pcb = [sp](int done, int total) { sp->reportProgress(done, total); };
            CancelCallback ccb = [sp]() { return sp->shouldCancel(); };
            RenderStats stats;
            {
                py::gil_scoped_release release;
                stats = r.render(pcb, ccb);
            }
            state.rethrow();
            return statsToDict(stats);
        }, py::arg("progress") = py::none(), py::arg("cancel") = py::none(),
           "Runs all passes; progress(done, total) after each, cancel() -> bool polled per tile. Returns stats.")
        .def("render_pass", [](Renderer& r, const py::object& cancel) {
            CallbackState state;
            state.cancel = callableOrNull(cancel, "cancel");
            CallbackState* sp = &state;
            CancelCallback ccb = [sp]() { return sp->shouldCancel(); };
            bool ok;
            {
                py::gil_scoped_release release;
                ok = r.renderPass(ccb);
            }
            state.rethrow();
            return ok;
        }, py::arg("cancel") = py::none(), "One more pass; False if cancelled")
        .def_property_readonly("film", &Renderer::film, py::return_value_policy::reference_internal)
        .def_property_readonly("stats", [](const Renderer& r) { return statsToDict(r.stats()); })
        .def_property_readonly("settings", &Renderer::settings);

    volphoton::bindings::registerImage(m);
    volphoton::bindings::registerVdbTestHelpers(m);
    volphoton::bindings::registerGltf(m);
    volphoton::bindings::registerTranslate(m);
    volphoton::bindings::bindVdbGuard(m);
}
