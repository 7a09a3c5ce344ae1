// volphoton._core: lights (and their environment images), the camera, surface materials (with
// UsdPreviewSurface's rules), meshes, instances and scenes.
#include "bindings.h"
#include "core/camera.h"
#include "core/lights.h"
#include "core/previewSurface.h"
#include "core/scene.h"

namespace py = pybind11;

namespace volphoton::bindings {
namespace {

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


}  // namespace

void bindScene(py::module_& m) {
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
        .def_readwrite("emissive_mesh_lights", &SceneDesc::emissiveMeshLights,
                       "False: emissive meshes are found by hits only, not sampled as lights (benchmarks)")
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
}

}  // namespace volphoton::bindings
