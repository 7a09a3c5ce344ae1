// volphoton._core: the diagnostic sink, render settings, the film and the renderer, with the
// progress / cancel callbacks and Ctrl-C handling of render() (threading rules in bindings.cpp).
#include <atomic>
#include <mutex>
#include <thread>

#include "bindings.h"
#include "core/diagnostics.h"
#include "core/integrator.h"
#include "core/photonCache.h"
#include "core/translate/settings.h"

namespace py = pybind11;

namespace volphoton::bindings {
namespace {

const char* severityName(Severity s) {
    return s == Severity::Error ? "error" : s == Severity::Warning ? "warning" : "info";
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
    d["photons_per_pass"] = s.photonsPerPass;
    d["photons_per_pass_resized"] = s.photonsPerPassResized;
    d["photon_variance_share"] = s.photonVarianceShare;
    d["measured_photon_cost"] = s.measuredPhotonCost;
    d["measured_path_tracer_cost"] = s.measuredPathTracerCost;
    d["photon_work_ratio"] = s.photonWorkRatio;
    d["camera_pass_work"] = py::dict(py::arg("rays") = s.cameraWork.rays, py::arg("lookups") = s.cameraWork.lookups);
    d["photon_work"] = py::dict(py::arg("rays") = s.photonWork.rays, py::arg("lookups") = s.photonWork.lookups);
    d["gather_work"] = py::dict(py::arg("rays") = s.gatherWork.rays, py::arg("lookups") = s.gatherWork.lookups,
                                py::arg("gathers") = s.gatherWork.gathers);
    d["photon_passes_reused"] = s.photonPassesReused;
    d["photons_reused"] = s.photonsReused;
    d["multiple_to_single_ratio"] = s.multipleToSingleRatio;
    d["photon_map_bytes"] = s.photonMapBytes;
    d["photons_thinned"] = s.photonsThinned;
    d["photons_radius_capped"] = s.photonsRadiusCapped;
    d["passes_run"] = s.passesRun;
    d["passes_skipped"] = s.passesSkipped;
    d["integrator_used"] = s.integratorUsed;
    d["integrator_reason"] = s.integratorReason;
    d["cancelled"] = s.cancelled;
    d["active_pixels"] = s.activePixels;
    d["median_relative_error"] = s.medianRelativeError;
    d["stop_reason"] = s.stopReason;
    return d;
}

py::dict settingsToDict(const RenderSettings& s) {
    py::dict d;
    d["integrator"] = translate::integratorName(s.integrator);
    d["width"] = s.width;
    d["height"] = s.height;
    d["samplesPerPixel"] = s.samplesPerPixel;
    d["noiseTarget"] = s.noiseTarget;
    d["timeLimit"] = s.timeLimit;
    d["maxSamplesPerPixel"] = s.maxSamplesPerPixel;
    d["maxDepth"] = s.maxDepth;
    d["rouletteDepth"] = s.rouletteDepth;
    d["seed"] = s.seed;
    d["threads"] = s.threads;
    d["photonsPerPass"] = s.photonsPerPass;
    d["initialRadius"] = s.initialRadius;
    d["radiusAlpha"] = s.radiusAlpha;
    d["photonRadiusMfp"] = s.photonRadiusMfp;
    d["photonBeams"] = s.photonBeams;
    d["combinedPhotonShare"] = s.combinedPhotonShare;
    d["stratifiedDims"] = s.stratifiedDims;
    d["marchStep"] = s.marchStep;
    d["singleScattering"] = s.singleScattering;
    d["multipleScattering"] = s.multipleScattering;
    d["multipleThreshold"] = s.multipleThreshold;
    d["transmittanceCutoff"] = s.transmittanceCutoff;
    d["photonMapBudgetBytes"] = s.photonMapBudgetBytes;
    d["domeVisibleToCamera"] = s.domeVisibleToCamera;
    d["guideAovs"] = s.guideAovs;
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

void bindRender(py::module_& m) {
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

    // ---- rendering ----------------------------------------------------------------------------
    py::class_<RenderSettings> rs(m, "RenderSettings");
    py::enum_<RenderSettings::Integrator>(rs, "Integrator")
        .value("PathTracer", RenderSettings::Integrator::PathTracer)
        .value("PhotonMap", RenderSettings::Integrator::PhotonMap)
        .value("Auto", RenderSettings::Integrator::Auto)
        .value("Combined", RenderSettings::Integrator::Combined);
    rs.def(py::init<>())
        .def_readwrite("integrator", &RenderSettings::integrator)
        .def_readwrite("width", &RenderSettings::width)
        .def_readwrite("height", &RenderSettings::height)
        .def_readwrite("samples_per_pixel", &RenderSettings::samplesPerPixel)
        .def_readwrite("noise_target", &RenderSettings::noiseTarget)
        .def_readwrite("time_limit", &RenderSettings::timeLimit)
        .def_readwrite("max_samples_per_pixel", &RenderSettings::maxSamplesPerPixel)
        .def_readwrite("max_depth", &RenderSettings::maxDepth)
        .def_readwrite("roulette_depth", &RenderSettings::rouletteDepth)
        .def_readwrite("seed", &RenderSettings::seed)
        .def_readwrite("threads", &RenderSettings::threads)
        .def_readwrite("photons_per_pass", &RenderSettings::photonsPerPass)
        .def_readwrite("initial_radius", &RenderSettings::initialRadius)
        .def_readwrite("radius_alpha", &RenderSettings::radiusAlpha)
        .def_readwrite("photon_radius_mfp", &RenderSettings::photonRadiusMfp)
        .def_readwrite("photon_beams", &RenderSettings::photonBeams)
        .def_readwrite("combined_photon_share", &RenderSettings::combinedPhotonShare)
        .def_readwrite("stratified_dims", &RenderSettings::stratifiedDims)
        .def_readwrite("march_step", &RenderSettings::marchStep)
        .def_readwrite("single_scattering", &RenderSettings::singleScattering)
        .def_readwrite("multiple_scattering", &RenderSettings::multipleScattering)
        .def_readwrite("multiple_threshold", &RenderSettings::multipleThreshold)
        .def_readwrite("transmittance_cutoff", &RenderSettings::transmittanceCutoff)
        .def_readwrite("photon_map_budget_bytes", &RenderSettings::photonMapBudgetBytes)
        .def_readwrite("dome_visible_to_camera", &RenderSettings::domeVisibleToCamera)
        .def_readwrite("guide_aovs", &RenderSettings::guideAovs)
        .def_readwrite("max_grid_voxels", &RenderSettings::maxGridVoxels)
        .def("to_dict", &settingsToDict, "Settings under their documented (integrator.h) names")
        .def("__repr__", [](const RenderSettings& s) { return py::repr(settingsToDict(s)).cast<std::string>(); });

    py::class_<Film> film(m, "Film");
    py::enum_<Film::Aov>(film, "Aov")
        .value("Beauty", Film::Beauty)
        .value("Single", Film::Single)
        .value("Multiple", Film::Multiple)
        .value("Emission", Film::Emission)
        .value("Surface", Film::Surface)
        .value("Albedo", Film::Albedo)
        .value("Normal", Film::Normal);
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
        .def("relative_error", [](const Film& f) { return imageArray(f.resolveRelativeError(), f.width(), f.height(), 1); },
             "(H, W) float32 estimated relative error of the beauty (Film::resolveRelativeError; inf below 2 samples)")
        .def_property_readonly("beauty", [](const Film& f) { return imageArray(f.resolveRgb(Film::Beauty), f.width(), f.height(), 3); })
        .def_property_readonly("single", [](const Film& f) { return imageArray(f.resolveRgb(Film::Single), f.width(), f.height(), 3); })
        .def_property_readonly("multiple", [](const Film& f) { return imageArray(f.resolveRgb(Film::Multiple), f.width(), f.height(), 3); })
        .def_property_readonly("emission", [](const Film& f) { return imageArray(f.resolveRgb(Film::Emission), f.width(), f.height(), 3); })
        .def_property_readonly("surface", [](const Film& f) { return imageArray(f.resolveRgb(Film::Surface), f.width(), f.height(), 3); })
        .def_property_readonly("albedo", [](const Film& f) { return imageArray(f.resolveRgb(Film::Albedo), f.width(), f.height(), 3); },
                               "denoiser guide (RenderSettings.guide_aovs; zero without it)")
        .def_property_readonly("normal", [](const Film& f) { return imageArray(f.resolveRgb(Film::Normal), f.width(), f.height(), 3); },
                               "denoiser guide (RenderSettings.guide_aovs; zero without it)");

    py::class_<PhotonCache, std::shared_ptr<PhotonCache>>(m, "PhotonCache",
        "Photon maps kept across renders of one scene content that differ in camera, image size or passes "
        "(core/photonCache.h). Drop it when lights, media or geometry change.")
        .def(py::init<>())
        .def_property_readonly("passes", &PhotonCache::passes, "photon passes kept")
        .def_property_readonly("bytes", &PhotonCache::bytes)
        .def_property_readonly("photons_per_pass", &PhotonCache::photonsPerPass)
        .def("clear", &PhotonCache::clear);

    m.def("choose_integrator", [](std::shared_ptr<Scene> scene, const RenderSettings& settings) {
        if (!scene) throw py::value_error("choose_integrator: scene is None");
        IntegratorChoice c = chooseIntegrator(*scene, settings);
        py::dict d;
        d["integrator"] = c.integrator == RenderSettings::Integrator::Combined ? "combined" : "pathTracer";
        d["reason"] = c.reason;
        d["photons_only"] = c.photonsOnly;
        d["open_media_by_photons"] = c.openMediaByPhotons;
        d["photon_beams"] = c.photonBeams;
        return d;
    }, py::arg("scene"), py::arg("settings"),
       "What integrator = auto would render `scene` with at these settings, and why (core chooseIntegrator)");

    py::class_<Renderer, std::shared_ptr<Renderer>>(m, "Renderer")
        .def(py::init([](std::shared_ptr<Scene> scene, const RenderSettings& settings, std::shared_ptr<PhotonCache> cache) {
            if (!scene) throw py::value_error("Renderer: scene is None");
            py::gil_scoped_release release;
            return std::make_shared<Renderer>(scene, settings, std::move(cache));
        }), py::arg("scene"), py::arg("settings"), py::arg("photon_cache") = py::none(),
           "photon_cache: a PhotonCache shared by renders of one scene content (photon maps reused)")
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
           "Runs passes until finished() (samplesPerPixel, or the noise target / time limit / sample cap); "
           "progress(done, estimated total) after each, cancel() -> bool polled per tile. Returns stats.")
        .def("finished", &Renderer::finished, "True when the stopping rule says no further pass (stats['stop_reason'])")
        .def("estimated_passes", &Renderer::estimatedPasses)
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
}

}  // namespace volphoton::bindings
