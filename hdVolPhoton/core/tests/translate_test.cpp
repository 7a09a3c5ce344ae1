// The translation layer (core/translate/): the reader's rules, the medium cache key, the light rules
// and the settings table. The USD side of the same rules is tested through both front ends
// (testenv/test_schema.py, testenv/hydra/test_parity.py).
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "core/translate/light.h"
#include "core/translate/medium.h"
#include "core/translate/settings.h"
#include "core/translate/volume.h"
#include "core/proceduralCloud.h"

using namespace volphoton;
using namespace volphoton::translate;

namespace {

MediumContext volumeContext() {
    MediumContext c;
    c.isVolume = true;
    c.hasApi = true;
    c.typeName = "Volume";
    return c;
}

bool hasDiagnostic(const Diagnostics& d, Severity s, const std::string& attribute) {
    for (const Diagnostic& x : d.list())
        if (x.severity == s && x.attribute == attribute) return true;
    return false;
}

}  // namespace

TEST(TranslateMedium, DefaultsAreTheSchemaFallbacks) {
    AttributeRecord r;
    r.primPath = "/fog";
    Diagnostics d;
    auto m = readMedium(r, volumeContext(), d);
    ASSERT_TRUE(m);
    EXPECT_TRUE(d.list().empty());
    EXPECT_EQ(m->density, 1.0);
    EXPECT_EQ(m->albedo, Spectrum(0.8));
    EXPECT_EQ(m->phase.kind, "henyeyGreenstein");
    EXPECT_EQ(m->densityMode, "constant");
    EXPECT_EQ(m->expUp, Vec3(0, 1, 0));
    for (const AttributeInfo& a : mediumAttributes()) EXPECT_EQ(a.name.rfind("volphoton:", 0), 0u) << a.name;
}

TEST(TranslateMedium, ClampsWarnsAndNamesTheAttribute) {
    AttributeRecord r;
    r.primPath = "/fog";
    r.set("volphoton:phase:g", 1.5);
    r.set("volphoton:density", std::string("thick"));
    r.set("volphoton:albedo", Vec3(1.5, 0.5, -1));
    Diagnostics d;
    auto m = readMedium(r, volumeContext(), d);
    EXPECT_EQ(m->phase.g, GLimit);
    EXPECT_EQ(m->density, 1.0);
    EXPECT_EQ(m->albedo, Spectrum(1.0, 0.5, 0.0));
    EXPECT_TRUE(hasDiagnostic(d, Severity::Warning, "volphoton:phase:g"));
    EXPECT_TRUE(hasDiagnostic(d, Severity::Error, "volphoton:density"));
    EXPECT_TRUE(hasDiagnostic(d, Severity::Warning, "volphoton:albedo"));
    bool named = false;
    for (const Diagnostic& x : d.list()) named |= x.text().rfind("warning: /fog.volphoton:phase:g: g = 1.5 is outside (-1, 1)", 0) == 0;
    EXPECT_TRUE(named);
}

TEST(TranslateMedium, MixtureLobesAndStageUpAxis) {
    AttributeRecord r;
    r.primPath = "/haze";
    r.set("volphoton:phase", std::string("mixture"));
    r.set(lobeAttribute("fwd", "g"), 0.8);
    r.set(lobeAttribute("fwd", "weight"), 3.0);
    r.set(lobeAttribute("back", "phase"), std::string("rayleigh"));
    MediumContext c = volumeContext();
    c.lobeNames = {"fwd", "back"};
    c.stageUp = Vec3(0, 0, 1);
    Diagnostics d;
    auto m = readMedium(r, c, d);
    ASSERT_EQ(m->phase.lobes.size(), 2u);
    EXPECT_EQ(m->phase.lobes[0].first, 3.0);
    EXPECT_EQ(m->phase.lobes[0].second.g, 0.8);
    EXPECT_EQ(m->phase.lobes[1].second.kind, "rayleigh");
    EXPECT_EQ(m->expUp, Vec3(0, 0, 1));
    // The mixture's mean cosine is the weighted mean of its lobes': (3 * 0.8 + 1 * 0) / 4.
    EXPECT_NEAR(buildPhase(m->phase)->meanCosine(), 0.6, 1e-6);
}

TEST(TranslateMedium, KeyDistinguishesEveryPhaseParameter) {
    MediumParams a;
    a.phase.kind = "schlick";
    a.phase.k = 0.8;
    MediumParams b = a;
    b.phase.k = -0.8;
    EXPECT_NE(mediumKey(a), mediumKey(b));
    b = a;
    b.phase.x = 0.5;
    EXPECT_NE(mediumKey(a), mediumKey(b));
    b = a;
    b.phase.table = {1, 2};
    EXPECT_NE(mediumKey(a), mediumKey(b));
    EXPECT_EQ(mediumKey(a), mediumKey(MediumParams(a)));
}

TEST(TranslateMedium, PresetReplacesTheCoefficients) {
    MediumParams m;
    m.primPath = "/ketchup";
    m.preset = "ketchup";
    Diagnostics d;
    EffectiveCoefficients c = effectiveCoefficients(m, d);
    EXPECT_TRUE(d.list().empty());
    // ketchup (Jensen et al. 2001): sigma_s' = (0.18, 0.07, 0.03), sigma_a = (0.061, 0.97, 1.45) per mm.
    EXPECT_NEAR(c.density, 0.03 + 1.45, 1e-12);  // the largest sigma_t (blue)
    EXPECT_NEAR(c.albedo[0], 0.18 / (0.18 + 0.061), 1e-12);
    m.preset = "tomato";
    effectiveCoefficients(m, d);
    EXPECT_TRUE(hasDiagnostic(d, Severity::Error, "volphoton:preset"));
}

TEST(TranslateVolume, GridFieldsSelectGridsByNameFromTheDensityFile) {
    namespace fs = std::filesystem;
    const fs::path dir = fs::path(::testing::TempDir()) / "translate_volume";
    fs::create_directories(dir);
    const std::string file = (dir / "cloud.vdb").string(), other = (dir / "other.vdb").string();
    writeProceduralCloudVdb(file, 8, 1.0 / 8, 1);
    writeProceduralCloudVdb(other, 8, 1.0 / 8, 2);
    const fs::path alias = dir / "alias.vdb";  // another spelling of the same file
    fs::remove(alias);
    fs::create_symlink(file, alias);

    MediumParams params;
    std::vector<GridFieldInput> fields = {
        {"density", "/V/density", file, "", 1},           // no fieldName: the slot's name; fieldIndex 1 warned
        {"temperature", "/V/temp", alias.string(), "heat", -1},  // same file through a link: kept
        {"emission", "/V/glow", other, "density", -1},     // another file: error, ignored
    };
    Diagnostics d;
    std::optional<GridMediumDesc> g = gridMediumFromFields("/V", params, Affine{}, fields, 1234, d);
    ASSERT_TRUE(g);
    EXPECT_EQ(g->filePath, file);
    EXPECT_EQ(g->densityGrid, "density");
    EXPECT_EQ(g->temperatureGrid, "heat");
    EXPECT_EQ(g->emissionGrid, "");
    EXPECT_EQ(g->maxActiveVoxels, 1234u);
    EXPECT_TRUE(hasDiagnostic(d, Severity::Warning, "fieldIndex"));
    EXPECT_TRUE(hasDiagnostic(d, Severity::Error, "filePath"));
    ASSERT_EQ(d.list().size(), 2u);

    // No density file: nothing to build, and nothing to say (the field's reader reported it).
    Diagnostics none;
    EXPECT_FALSE(gridMediumFromFields("/V", params, Affine{}, {{"density", "/V/density", "", "", -1}}, 0, none));
    EXPECT_FALSE(gridMediumFromFields("/V", params, Affine{}, {{"emission", "/V/glow", file, "", -1}}, 0, none));
    EXPECT_TRUE(gridMediumFromFields("/V", params, Affine{}, {{"density", "/V/density", file, "", 0}}, 0, none));
    EXPECT_TRUE(none.list().empty());  // fieldIndex 0 is the grid taken: no warning

    // Loading: a missing grid is the asset's fieldName's fault, an unreadable file its filePath's.
    Diagnostics load;
    GridMediumDesc good = *g;
    good.temperatureGrid.clear();
    EXPECT_TRUE(loadGridMediumReported("/V", "/V/density", good, load));
    EXPECT_TRUE(load.list().empty());
    GridMediumDesc missingGrid = good;
    missingGrid.densityGrid = "smoke";
    EXPECT_FALSE(loadGridMediumReported("/V", "/V/density", missingGrid, load));
    EXPECT_TRUE(hasDiagnostic(load, Severity::Error, "fieldName"));
    GridMediumDesc missingFile = good;
    missingFile.filePath = (dir / "absent.vdb").string();
    Diagnostics load2;
    EXPECT_FALSE(loadGridMediumReported("/V", "/V/density", missingFile, load2));
    EXPECT_TRUE(hasDiagnostic(load2, Severity::Error, "filePath"));
}

TEST(TranslateLight, BlackbodyIsWhiteAt6500KAndWarmBelow) {
    Spectrum w = usdLuxBlackbody(6500);
    EXPECT_NEAR(luminance(w), 1.0, 1e-9);
    EXPECT_NEAR(w[0], w[2], 0.02);  // UsdLux normalises 6500 K to (nearly) white
    Spectrum warm = usdLuxBlackbody(2500);
    EXPECT_GT(warm[0], 2 * warm[2]);
    EXPECT_EQ(usdLuxBlackbody(500), usdLuxBlackbody(1000));   // clamped to the table
    EXPECT_EQ(usdLuxBlackbody(2e4), usdLuxBlackbody(10000));
}

TEST(TranslateLight, NegativeChannelsAreClampedWithAWarning) {
    AttributeRecord r;
    r.primPath = "/key";
    r.set("inputs:color", Vec3(1, -0.5, 1));
    r.set("inputs:radius", 0.0);
    LightContext c;
    c.kind = "sphere";
    Diagnostics d;
    LightResult l = translateLight(r, c, d);
    ASSERT_TRUE(l.light);
    EXPECT_EQ(l.emission, Spectrum(1, 0, 1));
    EXPECT_TRUE(hasDiagnostic(d, Severity::Warning, "inputs:color"));
    EXPECT_EQ(l.kind, "point");
}

TEST(TranslateLight, ColorTemperatureMultipliesTheColour) {
    AttributeRecord r;
    r.primPath = "/warm";
    r.set("inputs:enableColorTemperature", true);
    r.set("inputs:colorTemperature", 2500.0);
    r.set("inputs:normalize", true);  // irradiance = s
    LightContext c;
    c.kind = "distant";
    Diagnostics d;
    LightResult l = translateLight(r, c, d);
    Spectrum bb = usdLuxBlackbody(2500);
    for (int i = 0; i < 3; ++i) EXPECT_DOUBLE_EQ(l.emission[i], bb[i]);
}

TEST(TranslateLight, MeshLightIsTheMeshSurfaceEmission) {
    AttributeRecord r;
    r.primPath = "/panel";
    r.set("inputs:intensity", 8.0);
    r.set("inputs:color", Vec3(1, 0.5, 0.25));
    r.set("inputs:normalize", true);
    LightContext c;
    c.kind = "mesh";
    c.meshArea = 4.0;
    Diagnostics d;
    LightResult l = translateLight(r, c, d);
    EXPECT_FALSE(l.light);  // the Scene makes the mesh light from the surface
    EXPECT_EQ(l.kind, "mesh");
    EXPECT_EQ(l.emission, Spectrum(2, 1, 0.5));  // s / world area
    EXPECT_EQ(l.materialSyncMode, "materialGlowTintsLight");  // MeshLightAPI's fallback
    EXPECT_TRUE(d.list().empty());

    SurfaceMaterial glowing;
    glowing.albedo = Spectrum(0.3);
    glowing.emission = Spectrum(0.5, 1, 2);
    SurfaceMaterial m = meshLightSurface(l, glowing);  // tinted by the material's glow
    EXPECT_EQ(m.emission, Spectrum(1, 1, 1));
    EXPECT_EQ(m.albedo, Spectrum(0.3));
    SurfaceMaterial plain;
    plain.albedo = Spectrum(0.3);
    EXPECT_EQ(meshLightSurface(l, plain).emission, l.emission);  // no glow: the light's own
    l.materialSyncMode = "independent";
    EXPECT_EQ(meshLightSurface(l, glowing).emission, l.emission);
    l.materialSyncMode = "noMaterialResponse";
    EXPECT_EQ(meshLightSurface(l, glowing).albedo, Spectrum(0.0));
    SurfaceMaterial glass;
    glass.kind = SurfaceMaterial::Kind::Dielectric;
    EXPECT_EQ(meshLightSurface(l, glass).kind, SurfaceMaterial::Kind::Lambertian);

    r.set("light:materialSyncMode", std::string("glow"));
    Diagnostics bad;
    EXPECT_EQ(translateLight(r, c, bad).materialSyncMode, "materialGlowTintsLight");
    EXPECT_TRUE(hasDiagnostic(bad, Severity::Warning, "light:materialSyncMode"));
}

TEST(TranslateSettings, TableDefaultsAndValidation) {
    RenderSettings defaults;
    const SettingInfo* depth = findSetting("maxDepth");
    ASSERT_TRUE(depth);
    EXPECT_EQ(std::get<int64_t>(depth->defaultValue()), defaults.maxDepth);
    RenderSettings s;
    Diagnostics d;
    EXPECT_TRUE(applySetting(s, "maxDepth", AttrValue(7.0), d));  // an integral double is an int
    EXPECT_EQ(s.maxDepth, 7);
    EXPECT_FALSE(applySetting(s, "maxDepth", AttrValue(7.5), d));
    EXPECT_TRUE(hasDiagnostic(d, Severity::Error, "volphoton:maxDepth"));
    EXPECT_TRUE(applySetting(s, "radiusAlpha", AttrValue(7.0), d));
    EXPECT_EQ(s.radiusAlpha, 1.0);
    EXPECT_TRUE(hasDiagnostic(d, Severity::Warning, "volphoton:radiusAlpha"));
    EXPECT_TRUE(applySetting(s, "integrator", AttrValue(std::string("photonMap")), d));
    EXPECT_EQ(s.integrator, RenderSettings::Integrator::PhotonMap);
    EXPECT_FALSE(applySetting(s, "integrator", AttrValue(std::string("bdpt")), d));
    EXPECT_FALSE(applySetting(s, "bogus", AttrValue(1.0), d));
    EXPECT_TRUE(hasDiagnostic(d, Severity::Warning, "volphoton:bogus"));
    for (const SettingInfo& info : renderSettingsTable()) {
        RenderSettings t;
        Diagnostics none;
        EXPECT_TRUE(applySetting(t, info.name, info.defaultValue(), none)) << info.name;  // defaults are valid
        EXPECT_TRUE(none.list().empty()) << info.name;
    }
}
