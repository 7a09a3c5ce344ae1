// volphoton._core: the translation layer (core/translate/): the usd-core front end reads attributes
// off the stage into plain Python values and hands them here; every default, range, rule and message
// is the C++ one the Hydra delegate also calls.
//
// Attribute values (AttributeRecord.values): bool, int, float, str, a 3-tuple (a vector or colour),
// a list of numbers (an array). Anything else arrives as "unusable" and gets an error naming its type.
// Diagnostics come back as (severity, prim, attribute, message) tuples.
#include <pybind11/functional.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "bindings.h"
#include "core/presets.h"
#include "core/translate/light.h"
#include "core/translate/medium.h"
#include "core/translate/settings.h"
#include "core/translate/volume.h"

namespace py = pybind11;
using namespace volphoton;
using namespace volphoton::translate;

namespace {

AttrValue toAttrValue(const py::handle& v) {
    if (py::isinstance<py::bool_>(v)) return v.cast<bool>();
    if (py::isinstance<py::int_>(v)) {
        try {
            return v.cast<int64_t>();
        } catch (const py::cast_error&) {
            return v.cast<double>();
        }
    }
    if (py::isinstance<py::float_>(v)) return v.cast<double>();
    if (py::isinstance<py::str>(v)) return v.cast<std::string>();
    if (py::isinstance<py::tuple>(v) && py::len(v) == 3) {
        try {
            return v.cast<Vec3>();
        } catch (const py::cast_error&) {
        }
    }
    if (py::isinstance<py::list>(v) || py::isinstance<py::tuple>(v)) {
        try {
            return v.cast<std::vector<double>>();
        } catch (const py::cast_error&) {
        }
    }
    return Unusable{py::str(py::type::of(v).attr("__name__")).cast<std::string>()};
}

AttributeRecord toRecord(const std::string& prim, const py::dict& values, const py::iterable& authored) {
    AttributeRecord r;
    r.primPath = prim;
    for (auto [k, v] : values) r.values[k.cast<std::string>()] = toAttrValue(v);
    for (auto a : authored) r.authored.insert(a.cast<std::string>());
    return r;
}

py::list toPy(const Diagnostics& d) {
    py::list out;
    for (const Diagnostic& x : d.list()) {
        const char* s = x.severity == Severity::Error ? "error" : x.severity == Severity::Warning ? "warning" : "info";
        out.append(py::make_tuple(s, x.primPath, x.attribute, x.message));
    }
    return out;
}

py::object attrToPy(const AttrValue& v) {
    return std::visit([](const auto& x) -> py::object {
        using T = std::decay_t<decltype(x)>;
        if constexpr (std::is_same_v<T, Unusable>) return py::none();
        else return py::cast(x);
    }, v);
}


}  // namespace

namespace volphoton::bindings {

void bindTranslate(py::module_& m) {
    py::class_<PhaseParams>(m, "PhaseParams", "A validated phase function (core/translate/medium.h)")
        .def(py::init<>())
        .def_readwrite("kind", &PhaseParams::kind)
        .def_readwrite("g", &PhaseParams::g)
        .def_readwrite("k", &PhaseParams::k)
        .def_readwrite("x", &PhaseParams::x)
        .def_readwrite("table", &PhaseParams::table)
        .def_readwrite("lobes", &PhaseParams::lobes);
    py::class_<MediumParams>(m, "MediumParams", "A medium prim's validated parameters (core/translate/medium.h)")
        .def(py::init<>())
        .def_readwrite("prim_path", &MediumParams::primPath)
        .def_readwrite("density", &MediumParams::density)
        .def_readwrite("albedo", &MediumParams::albedo)
        .def_readwrite("extinction_color", &MediumParams::extinctionColor)
        .def_readwrite("emission", &MediumParams::emission)
        .def_readwrite("emission_scale", &MediumParams::emissionScale)
        .def_readwrite("temperature_scale", &MediumParams::temperatureScale)
        .def_readwrite("phase", &MediumParams::phase)
        .def_readwrite("density_mode", &MediumParams::densityMode)
        .def_readwrite("exp_a", &MediumParams::expA)
        .def_readwrite("exp_b", &MediumParams::expB)
        .def_readwrite("exp_up", &MediumParams::expUp)
        .def_readwrite("exp_origin", &MediumParams::expOrigin)
        .def_readwrite("ior", &MediumParams::ior)
        .def_readwrite("preset", &MediumParams::preset)
        .def_readwrite("scene_units_per_mm", &MediumParams::sceneUnitsPerMm)
        .def_readwrite("bounds", &MediumParams::bounds)
        .def("key", &mediumKey, "a text that differs whenever any parameter differs");

    m.def("phase_kinds", &phaseKinds);
    m.def("density_modes", &densityModes);
    auto attributeTable = [](const std::vector<AttributeInfo>& t) {
        py::list out;  // [(name, fallback or None)]
        for (const AttributeInfo& a : t) out.append(py::make_tuple(a.name, a.fallback ? attrToPy(*a.fallback) : py::none()));
        return out;
    };
    m.def("medium_attributes", [=] { return attributeTable(mediumAttributes()); },
          "VolPhotonMediumAPI attributes the reader understands: [(name, fallback or None)]");
    m.def("lobe_properties", [=] { return attributeTable(lobeProperties()); },
          "VolPhotonPhaseLobeAPI properties by base name: [(name, fallback or None)]");
    m.def("light_attribute_names", &lightAttributeNames);
    m.def("translate_g_limit", [] { return GLimit; });

    m.def("read_medium", [](const std::string& prim, const py::dict& values, const py::iterable& authored, bool isVolume,
                            bool isGprim, bool hasApi, bool schemaRegistered, const std::string& typeName,
                            bool hasDensityField, const Vec3& stageUp, const std::vector<std::string>& lobeNames) {
        MediumContext c;
        c.isVolume = isVolume;
        c.isGprim = isGprim;
        c.hasApi = hasApi;
        c.schemaRegistered = schemaRegistered;
        c.typeName = typeName;
        c.hasDensityField = hasDensityField;
        c.stageUp = stageUp;
        c.lobeNames = lobeNames;
        Diagnostics d;
        std::optional<MediumParams> p = readMedium(toRecord(prim, values, authored), c, d);
        return py::make_tuple(p ? py::cast(*p) : py::none(), toPy(d));
    }, py::arg("prim"), py::arg("values"), py::arg("authored"), py::arg("is_volume"), py::arg("is_gprim"),
       py::arg("has_api"), py::arg("schema_registered"), py::arg("type_name"), py::arg("has_density_field"),
       py::arg("stage_up"), py::arg("lobe_names"),
       "(MediumParams or None, diagnostics): the medium reader of core/translate/medium.h");
    m.def("build_phase", [](const PhaseParams& p) { return mutableCopy(buildPhase(p)); }, py::arg("phase"));
    m.def("build_procedural_medium", [](const MediumParams& p, const Affine& world, bool useBounds) {
        Diagnostics d;
        std::string kind;
        MediumPtr medium = buildProceduralMedium(p, world, useBounds, d, &kind);
        return py::make_tuple(medium ? py::cast(mutableCopy(medium)) : py::none(), kind, toPy(d));
    }, py::arg("params"), py::arg("object_to_world"), py::arg("use_bounds"),
       "(Medium or None, 'homogeneous'|'exponential', diagnostics)");
    py::class_<GridFieldInput>(m, "GridFieldInput",
                               "An OpenVDBAsset bound to a volume's field:<slot> (core/translate/volume.h)")
        .def(py::init([](std::string slot, std::string primPath, std::string filePath, std::string fieldName,
                         int fieldIndex) {
                 return GridFieldInput{std::move(slot), std::move(primPath), std::move(filePath), std::move(fieldName),
                                       fieldIndex};
             }),
             py::arg("slot"), py::arg("prim_path"), py::arg("file_path"), py::arg("field_name") = "",
             py::arg("field_index") = -1);
    m.def("grid_medium_from_fields", [](const std::string& volumePath, const MediumParams& p, const Affine& world,
                                        const std::vector<GridFieldInput>& fields, std::uint64_t maxActiveVoxels) {
        Diagnostics d;
        std::optional<GridMediumDesc> g = gridMediumFromFields(volumePath, p, world, fields, maxActiveVoxels, d);
        return py::make_tuple(g ? py::cast(*g) : py::none(), toPy(d));
    }, py::arg("volume_path"), py::arg("params"), py::arg("object_to_world"), py::arg("fields"),
       py::arg("max_active_voxels"), "(GridMediumDesc or None when there is no density file, diagnostics)");
    m.def("load_grid_medium_reported", [](const std::string& volumePath, const std::string& densityPrim,
                                          const GridMediumDesc& desc) {
        Diagnostics d;
        MediumPtr medium;
        {
            py::gil_scoped_release release;
            medium = loadGridMediumReported(volumePath, densityPrim, desc, d);
        }
        return py::make_tuple(medium ? py::cast(mutableCopy(medium)) : py::none(), toPy(d));
    }, py::arg("volume_path"), py::arg("density_prim"), py::arg("desc"),
       "(Medium or None, diagnostics): loadGridMedium behind the reader guard, errors as diagnostics");
    m.def("effective_coefficients", [](const MediumParams& p) {
        Diagnostics d;
        EffectiveCoefficients c = effectiveCoefficients(p, d);
        return py::make_tuple(c.density, c.extinctionColor, c.albedo, toPy(d));
    }, py::arg("params"), "(density, extinction colour, albedo, diagnostics) after the preset");

    m.def("preset_coefficients", [](const std::string& name, double sceneUnitsPerMm, double g) {
        const SubsurfacePreset* preset = findSubsurfacePreset(name);
        if (!preset) throw py::key_error("unknown preset '" + name + "' (valid: " + subsurfacePresetNames() + ")");
        PresetCoefficients c = presetCoefficients(*preset, sceneUnitsPerMm, g);  // invalid_argument -> ValueError
        return py::make_tuple(c.sigma_s, c.sigma_a);
    }, py::arg("name"), py::arg("scene_units_per_mm") = 1.0, py::arg("g") = 0.0,
       "(sigma_s, sigma_a) in 1/scene unit of a measured material (core/presets.h)");
    m.def("usd_lux_blackbody", &usdLuxBlackbody, py::arg("kelvin"),
          "UsdLuxBlackbodyTemperatureAsRgb: RGB normalised to luminance 1");
    m.def("translate_light", [](const std::string& prim, const py::dict& values, const std::string& kind,
                                const std::string& typeName, const Affine& world, bool hasFilters,
                                const std::string& textureAssetPath, double meshArea) {
        LightContext c;
        c.meshArea = meshArea;
        c.kind = kind;
        c.typeName = typeName;
        c.lightToWorld = world;
        c.hasFilters = hasFilters;
        c.textureAssetPath = textureAssetPath;
        Diagnostics d;
        LightResult r = translateLight(toRecord(prim, values, py::list()), c, d);
        py::dict params;
        for (auto& [k, v] : r.scalars) params[py::str(k)] = v;
        for (auto& [k, v] : r.vectors) params[py::str(k)] = v;
        if (r.kind == "dome") params["texture"] = r.texture;
        if (r.kind == "mesh") params["material_sync_mode"] = r.materialSyncMode;
        if (params.contains("normalize")) params["normalize"] = params["normalize"].cast<double>() != 0;
        py::object light = r.light ? py::cast(mutableCopy(r.light)) : py::none();
        return py::make_tuple(light, r.kind, r.emission, r.quantity, params, toPy(d));
    }, py::arg("prim"), py::arg("values"), py::arg("kind"), py::arg("type_name"), py::arg("light_to_world"),
       py::arg("has_filters") = false, py::arg("texture_asset_path") = "", py::arg("mesh_area") = 0.0,
       "(Light or None, kind, emission, quantity, params, diagnostics): core/translate/light.h");
    m.def("mesh_world_area", [](const py::object& points, const std::vector<uint32_t>& indices, const Affine& world) {
        return meshWorldArea(bindings::arrayToVec3s(points, "points"), indices, world);
    }, py::arg("points"), py::arg("indices"), py::arg("to_world"),
          "World-space area of triangles (core/translate/light.h meshWorldArea)");
    m.def("mesh_light_surface", [](const Spectrum& emission, const std::string& materialSyncMode, const SurfaceMaterial& m) {
        LightResult light;
        light.emission = emission;
        light.materialSyncMode = materialSyncMode;
        return meshLightSurface(light, m);
    }, py::arg("emission"), py::arg("material_sync_mode"), py::arg("material"),
       "The SurfaceMaterial of a mesh with MeshLightAPI (core/translate/light.h meshLightSurface)");

    m.def("render_settings_table", [] {
        py::list out;
        for (const SettingInfo& s : renderSettingsTable()) {
            py::dict d;
            d["name"] = s.name;
            d["type"] = s.type == SettingType::Bool ? "bool" : s.type == SettingType::Int ? "int"
                      : s.type == SettingType::Double ? "double" : "choice";
            d["min"] = s.min;
            d["max"] = s.max;
            d["choices"] = s.choices;
            d["cli_flag"] = s.cliFlag;
            d["hydra_key"] = s.hydraKey;
            d["label"] = s.label;
            d["units"] = s.units;
            d["meaning"] = s.meaning;
            d["default"] = attrToPy(s.defaultValue());
            out.append(d);
        }
        return out;
    }, "Every render setting: name, type, min, max, choices, cli_flag, hydra_key, label, units, meaning, default");
    m.def("apply_setting", [](RenderSettings& s, const std::string& name, const py::handle& value, const std::string& prim) {
        Diagnostics d;
        bool ok = applySetting(s, name, toAttrValue(value), d, prim);
        return py::make_tuple(ok, toPy(d));
    }, py::arg("settings"), py::arg("name"), py::arg("value"), py::arg("prim") = "",
       "Validates and stores one setting: (stored, diagnostics)");
    m.def("get_setting", [](const RenderSettings& s, const std::string& name) {
        const SettingInfo* info = findSetting(name);
        if (!info) throw py::key_error(name);
        return attrToPy(info->get(s));
    }, py::arg("settings"), py::arg("name"));
}

}  // namespace volphoton::bindings
