// The render settings table: every user-facing setting once, with its type, default, range, command
// line flag and meaning. The usd-core front end (RenderSettings prim attributes `volphoton:<name>`,
// the CLI flags and their --help), the Hydra delegate (render-setting descriptors, the RenderSettings
// Bprim) and the README's settings table are generated from it or checked against it
// (testenv/test_settings_table.py). Defaults are those of a default-constructed RenderSettings.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "core/integrator.h"
#include "core/translate/record.h"

namespace volphoton::translate {

enum class SettingType { Bool, Int, Double, Choice };

struct SettingInfo {
    std::string name;                  ///< `volphoton:<name>` on a RenderSettings prim
    SettingType type;
    double min = 0, max = 0;           ///< Int/Double: valid range (outside: clamped with a warning)
    std::vector<std::string> choices;  ///< Choice: valid values
    std::string cliFlag;               ///< "--max-depth"; "" when the CLI has no flag for it
    std::string hydraKey;              ///< the delegate's setting key (HdRenderSettingsTokens name or volphoton:<name>)
    std::string label;                 ///< UI label (usdview's settings dialog)
    std::string units;
    std::string meaning;
    std::function<AttrValue(const RenderSettings&)> get;
    std::function<void(RenderSettings&, const AttrValue&)> set;  ///< takes a validated value of `type`

    AttrValue defaultValue() const { return get(RenderSettings{}); }
};

/// Every setting, in the order documented.
const std::vector<SettingInfo>& renderSettingsTable();
/// The entry called `name` (without the volphoton: prefix), or nullptr.
const SettingInfo* findSetting(const std::string& name);

/// Validates `value` (read from a RenderSettings prim, a CLI flag or a Hydra setting) for setting
/// `name` and stores it in `settings`. Unusable values (wrong type, NaN, unknown choice) are errors
/// and leave the setting unchanged; out-of-range numbers are clamped with a warning. Diagnostics name
/// `prim` and the attribute `volphoton:<name>`. Returns false when nothing was stored.
bool applySetting(RenderSettings& settings, const std::string& name, const AttrValue& value,
                  Diagnostics& diagnostics, const std::string& prim = "");

/// The integrator's name as a setting value ("pathTracer" / "photonMap" / "auto"), and back; parseIntegrator
/// also takes the CLI's lower-case spellings. False for anything else.
std::string integratorName(RenderSettings::Integrator integrator);
bool parseIntegrator(const std::string& text, RenderSettings::Integrator* out);

}  // namespace volphoton::translate
