// The translation layer's input and output: what a front end read off one prim, and what the
// translation had to say about it. Both front ends (the usd-core reader in
// hdVolPhoton/python/volphoton/ and the Hydra delegate in hdVolPhoton/hd/) fill an AttributeRecord
// with the values they find under USD's attribute names and hand it to the translate functions
// (medium.h, light.h, settings.h); every default, range, rule and message lives there, once.
//
// | AttrValue alternative   | what a front end puts there                                    |
// |-------------------------|----------------------------------------------------------------|
// | bool                    | bool attributes                                                |
// | int64_t                 | int, uint, int64 attributes                                    |
// | double                  | float, double, half attributes                                 |
// | Vec3                    | float3/double3/color3f/vector3f/point3f/normal3f values        |
// | std::string             | token, string and (resolved) asset attributes                  |
// | std::vector<double>     | float[]/double[] arrays and any other numeric tuple            |
// | Unusable                | a value of some other type (its type name, for the message)    |
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <variant>
#include <vector>

#include "core/diagnostics.h"
#include "core/math.h"

namespace volphoton::translate {

/// A value whose type no translate function can use; `typeName` names it in messages.
struct Unusable {
    std::string typeName;
    bool operator==(const Unusable& o) const { return typeName == o.typeName; }
};

using AttrValue = std::variant<bool, int64_t, double, Vec3, std::string, std::vector<double>, Unusable>;

/// "0.5", "(1, 0, 0)", "'thick'", "true": how a value is quoted in diagnostics.
std::string formatValue(const AttrValue& value);
std::string formatNumber(double x);  ///< %.6g
std::string formatVec3(const Vec3& v);

/// \class AttributeRecord
/// The values of one prim's attributes at one time, by USD attribute name. A name is present when
/// the attribute has a value (authored, or a schema fallback); `authored` lists the names with an
/// authored opinion.
struct AttributeRecord {
    std::string primPath;
    std::map<std::string, AttrValue> values;
    std::set<std::string> authored;

    const AttrValue* find(const std::string& name) const {
        auto it = values.find(name);
        return it == values.end() ? nullptr : &it->second;
    }
    bool isAuthored(const std::string& name) const { return authored.count(name) > 0; }
    /// Adds an authored value (for tests and front ends that only see authored values).
    void set(const std::string& name, AttrValue value) {
        values[name] = std::move(value);
        authored.insert(name);
    }
};

/// A problem found on a prim; text() gives "severity: /prim.attribute: message".
struct Diagnostic {
    Severity severity = Severity::Warning;
    std::string primPath;
    std::string attribute;  ///< property name; "" for the prim itself
    std::string message;
    std::string text() const;
};

/// Collects diagnostics for one prim (or several: each call names its prim).
class Diagnostics {
public:
    void error(const std::string& prim, const std::string& attribute, const std::string& message) {
        add(Severity::Error, prim, attribute, message);
    }
    void warn(const std::string& prim, const std::string& attribute, const std::string& message) {
        add(Severity::Warning, prim, attribute, message);
    }
    void add(Severity s, const std::string& prim, const std::string& attribute, const std::string& message) {
        list_.push_back({s, prim, attribute, message});
    }
    const std::vector<Diagnostic>& list() const { return list_; }
    bool hasErrors() const;
    void append(const Diagnostics& other) { list_.insert(list_.end(), other.list_.begin(), other.list_.end()); }

private:
    std::vector<Diagnostic> list_;
};

}  // namespace volphoton::translate
