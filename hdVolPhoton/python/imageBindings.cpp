// Image output for the front end: multi-layer OpenEXR (core/imageIO.h) and the OpenColorIO display
// transform from the renderer's linear scene-referred RGB to display-referred 8-bit.
//
// Colour management (OpenColorIO 2.1):
//   * no config given (the front end passes $OCIO when it is set): a config built in code, since
//     OCIO 2.1 has no built-in configs:
//       colour spaces  "Linear Rec.709 (sRGB)"  linear Rec.709 primaries, D65: the renderer's
//                                    working space (roles scene_linear, reference, default, rendering)
//                      sRGB          the IEC 61966-2-1 piecewise curve (ExponentWithLinearTransform
//                                    gamma 2.4, offset 0.055: linear slope 12.92 below 0.0031308)
//                      raw           data, no conversion (role data)
//       display sRGB, views "Standard" (sRGB) and "Raw"; default sRGB / Standard.
//   * a config file: its display/view (defaults: the config's default display and its default
//     view); the input colour space is the config's scene_linear role unless one is named.
// Display values are clamped to [0, 1] and rounded to 8 bits; NaN becomes 0.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <OpenColorIO/OpenColorIO.h>

#include <cmath>
#include <cstring>

#include "bindings.h"
#include "core/imageIO.h"

namespace py = pybind11;
namespace OCIO = OCIO_NAMESPACE;

namespace volphoton::bindings {
namespace {

OCIO::ConstConfigRcPtr builtinConfig() {
    static OCIO::ConstConfigRcPtr config = [] {
        OCIO::ConfigRcPtr cfg = OCIO::Config::Create();
        cfg->setDescription("volphoton built-in config: linear Rec.709 scene_linear, sRGB display");

        OCIO::ColorSpaceRcPtr lin = OCIO::ColorSpace::Create();
        lin->setName("Linear Rec.709 (sRGB)");
        lin->setFamily("Linear");
        lin->setEncoding("scene-linear");
        lin->setDescription("Scene-referred linear light, Rec.709 / sRGB primaries, D65 white point");
        cfg->addColorSpace(lin);

        OCIO::ColorSpaceRcPtr srgb = OCIO::ColorSpace::Create();
        srgb->setName("sRGB");
        srgb->setFamily("Display");
        srgb->setEncoding("sdr-video");
        srgb->setDescription("sRGB display encoding: IEC 61966-2-1 piecewise curve, Rec.709 primaries");
        OCIO::ExponentWithLinearTransformRcPtr curve = OCIO::ExponentWithLinearTransform::Create();
        const double gamma[4] = {2.4, 2.4, 2.4, 1.0};
        const double offset[4] = {0.055, 0.055, 0.055, 0.0};
        curve->setGamma(gamma);
        curve->setOffset(offset);
        // Forward = encoded -> linear, i.e. this colour space's "to reference" direction.
        srgb->setTransform(curve, OCIO::COLORSPACE_DIR_TO_REFERENCE);
        cfg->addColorSpace(srgb);

        OCIO::ColorSpaceRcPtr raw = OCIO::ColorSpace::Create();
        raw->setName("raw");
        raw->setFamily("Utility");
        raw->setIsData(true);
        raw->setDescription("Data: no colour conversion");
        cfg->addColorSpace(raw);

        cfg->setRole(OCIO::ROLE_SCENE_LINEAR, "Linear Rec.709 (sRGB)");
        cfg->setRole(OCIO::ROLE_REFERENCE, "Linear Rec.709 (sRGB)");
        cfg->setRole(OCIO::ROLE_DEFAULT, "Linear Rec.709 (sRGB)");
        cfg->setRole(OCIO::ROLE_RENDERING, "Linear Rec.709 (sRGB)");
        cfg->setRole(OCIO::ROLE_DATA, "raw");
        cfg->addDisplayView("sRGB", "Standard", "sRGB", "");
        cfg->addDisplayView("sRGB", "Raw", "raw", "");
        cfg->setActiveDisplays("sRGB");
        cfg->setActiveViews("Standard, Raw");
        cfg->validate();
        return OCIO::ConstConfigRcPtr(cfg);
    }();
    return config;
}

OCIO::ConstConfigRcPtr loadConfig(const std::string& path) {
    if (path.empty()) return builtinConfig();
    try {
        return OCIO::Config::CreateFromFile(path.c_str());
    } catch (const std::exception& e) {
        throw std::runtime_error("cannot load OpenColorIO config '" + path + "': " + e.what());
    }
}

std::vector<std::string> displayNames(const OCIO::ConstConfigRcPtr& cfg) {
    std::vector<std::string> out;
    for (int i = 0; i < cfg->getNumDisplays(); ++i) out.emplace_back(cfg->getDisplay(i));
    return out;
}

std::vector<std::string> viewNames(const OCIO::ConstConfigRcPtr& cfg, const std::string& display) {
    std::vector<std::string> out;
    for (int i = 0; i < cfg->getNumViews(display.c_str()); ++i) out.emplace_back(cfg->getView(display.c_str(), i));
    return out;
}

std::string join(const std::vector<std::string>& v) {
    std::string s;
    for (const auto& x : v) s += (s.empty() ? "" : ", ") + x;
    return s;
}

/// Display/view transform of one config, applied on the CPU.
class DisplayTransform {
public:
    DisplayTransform(const std::string& configPath, std::string display, std::string view, std::string input)
        : configPath_(configPath) {
        OCIO::ConstConfigRcPtr cfg = loadConfig(configPath);
        auto displays = displayNames(cfg);
        if (displays.empty()) throw std::runtime_error("OpenColorIO config '" + configName() + "' defines no display");
        if (display.empty()) display = cfg->getDefaultDisplay();
        if (std::find(displays.begin(), displays.end(), display) == displays.end())
            throw std::invalid_argument("unknown display '" + display + "' in OpenColorIO config '" + configName() +
                                        "' (displays: " + join(displays) + ")");
        auto views = viewNames(cfg, display);
        if (view.empty()) view = cfg->getDefaultView(display.c_str());
        if (std::find(views.begin(), views.end(), view) == views.end())
            throw std::invalid_argument("unknown view '" + view + "' for display '" + display + "' in OpenColorIO config '" +
                                        configName() + "' (views: " + join(views) + ")");
        if (input.empty()) input = cfg->hasRole(OCIO::ROLE_SCENE_LINEAR) ? OCIO::ROLE_SCENE_LINEAR : OCIO::ROLE_DEFAULT;
        if (!cfg->getColorSpace(input.c_str()))
            throw std::invalid_argument("unknown input colour space '" + input + "' in OpenColorIO config '" + configName() + "'");
        OCIO::ConstProcessorRcPtr proc = cfg->getProcessor(input.c_str(), display.c_str(), view.c_str(), OCIO::TRANSFORM_DIR_FORWARD);
        cpu_ = proc->getOptimizedCPUProcessor(OCIO::BIT_DEPTH_F32, OCIO::BIT_DEPTH_F32, OCIO::OPTIMIZATION_DEFAULT);
        display_ = display;
        view_ = view;
        input_ = cfg->getColorSpace(input.c_str())->getName();
        description_ = cfg->getDescription();
    }

    std::string configName() const { return configPath_.empty() ? "<built-in>" : configPath_; }

    /// (H, W, 3) float32 scene-linear -> (H, W, 3) float32 display values (not clamped).
    py::array_t<float> apply(py::array_t<float, py::array::c_style | py::array::forcecast> rgb) const {
        if (rgb.ndim() != 3 || rgb.shape(2) != 3) throw py::value_error("DisplayTransform: expected an (H, W, 3) array");
        py::array_t<float> out({rgb.shape(0), rgb.shape(1), static_cast<py::ssize_t>(3)});
        std::memcpy(out.mutable_data(), rgb.data(), sizeof(float) * static_cast<size_t>(rgb.size()));
        long w = static_cast<long>(rgb.shape(1)), h = static_cast<long>(rgb.shape(0));
        float* data = out.mutable_data();
        if (w > 0 && h > 0) {
            py::gil_scoped_release release;
            for (long i = 0; i < w * h * 3; ++i)
                if (!std::isfinite(data[i])) data[i] = std::isinf(data[i]) && data[i] > 0 ? 1e30f : 0.0f;
            OCIO::PackedImageDesc img(data, w, h, 3);
            cpu_->apply(img);
        }
        return out;
    }

    /// (H, W, 3) float32 scene-linear -> (H, W, 3) uint8 display-referred.
    py::array_t<uint8_t> toUint8(py::array_t<float, py::array::c_style | py::array::forcecast> rgb) const {
        py::array_t<float> disp = apply(rgb);
        py::array_t<uint8_t> out({disp.shape(0), disp.shape(1), static_cast<py::ssize_t>(3)});
        const float* s = disp.data();
        uint8_t* d = out.mutable_data();
        for (py::ssize_t i = 0; i < disp.size(); ++i) {
            float v = s[i];
            v = std::isnan(v) ? 0.0f : std::min(1.0f, std::max(0.0f, v));
            d[i] = static_cast<uint8_t>(std::lround(v * 255.0f));
        }
        return out;
    }

    std::string display_, view_, input_, description_;

private:
    std::string configPath_;
    OCIO::ConstCPUProcessorRcPtr cpu_;
};

std::vector<ExrChannel> channelsFromDict(const py::dict& planes, std::vector<py::array_t<float>>& keep, int* width,
                                         int* height) {
    std::vector<ExrChannel> channels;
    *width = *height = -1;
    for (auto item : planes) {
        std::string name = py::cast<std::string>(item.first);
        auto a = py::array_t<float, py::array::c_style | py::array::forcecast>::ensure(item.second);
        if (!a || a.ndim() != 2) throw py::value_error("write_exr: channel '" + name + "' must be an (H, W) array");
        if (*width < 0) {
            *height = static_cast<int>(a.shape(0));
            *width = static_cast<int>(a.shape(1));
        } else if (a.shape(0) != *height || a.shape(1) != *width) {
            throw py::value_error("write_exr: channel '" + name + "' has a different size from the others");
        }
        keep.push_back(a);
        channels.push_back({name, keep.back().data(), 1});
    }
    if (channels.empty()) throw py::value_error("write_exr: no channels");
    return channels;
}

}  // namespace

void bindImage(py::module_& m) {
    m.def("write_exr", [](const std::string& path, const py::dict& planes, const std::map<std::string, std::string>& attrs,
                          const std::string& compression) {
        std::vector<py::array_t<float>> keep;
        keep.reserve(planes.size());
        int w, h;
        std::vector<ExrChannel> channels = channelsFromDict(planes, keep, &w, &h);
        std::vector<std::pair<std::string, std::string>> a(attrs.begin(), attrs.end());
        ExrCompression c = compression == "none" ? ExrCompression::None
                           : compression == "piz" ? ExrCompression::Piz
                           : compression == "zip" ? ExrCompression::Zip
                                                  : throw py::value_error("write_exr: compression must be zip, piz or none");
        py::gil_scoped_release release;
        writeExr(path, w, h, channels, a, c);
    }, py::arg("path"), py::arg("channels"), py::arg("attributes") = std::map<std::string, std::string>(),
       py::arg("compression") = "zip",
       "Writes float32 planes {name: (H, W) array} as one scanline OpenEXR file with string attributes.");
    m.def("read_exr", [](const std::string& path) {
        ExrImage img;
        {
            py::gil_scoped_release release;
            img = readExr(path);
        }
        py::dict channels;
        for (auto& [name, plane] : img.channels) {
            py::array_t<float> a({img.height, img.width});
            std::copy(plane.begin(), plane.end(), a.mutable_data());
            channels[py::str(name)] = a;
        }
        return py::make_tuple(channels, img.attributes);
    }, py::arg("path"), "(channels {name: (H, W) float32}, string attributes) of an OpenEXR file");

    py::class_<DisplayTransform>(m, "DisplayTransform")
        .def(py::init<const std::string&, std::string, std::string, std::string>(), py::arg("config") = "",
             py::arg("display") = "", py::arg("view") = "", py::arg("input_colorspace") = "",
             "config: path of an OCIO config, '' = the built-in one; '' display/view = the config's defaults")
        .def("apply", &DisplayTransform::apply, py::arg("rgb"))
        .def("to_uint8", &DisplayTransform::toUint8, py::arg("rgb"))
        .def_readonly("display", &DisplayTransform::display_)
        .def_readonly("view", &DisplayTransform::view_)
        .def_readonly("input_colorspace", &DisplayTransform::input_)
        .def_readonly("description", &DisplayTransform::description_)
        .def_property_readonly("config", &DisplayTransform::configName);
    m.def("ocio_displays", [](const std::string& config) { return displayNames(loadConfig(config)); },
          py::arg("config") = "");
    m.def("ocio_views", [](const std::string& config, const std::string& display) {
        return viewNames(loadConfig(config), display);
    }, py::arg("config") = "", py::arg("display") = "");
    m.attr("OCIO_VERSION") = OCIO::GetVersion();
}

}  // namespace volphoton::bindings
