#include "core/translate/record.h"

#include <cstdio>

namespace volphoton::translate {

std::string formatNumber(double x) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.6g", x);
    return buf;
}

std::string formatVec3(const Vec3& v) {
    return "(" + formatNumber(v.x) + ", " + formatNumber(v.y) + ", " + formatNumber(v.z) + ")";
}

std::string formatValue(const AttrValue& value) {
    struct Visitor {
        std::string operator()(bool b) const { return b ? "true" : "false"; }
        std::string operator()(int64_t i) const { return std::to_string(i); }
        std::string operator()(double d) const { return formatNumber(d); }
        std::string operator()(const Vec3& v) const { return formatVec3(v); }
        std::string operator()(const std::string& s) const { return "'" + s + "'"; }
        std::string operator()(const std::vector<double>& a) const {
            std::string out = "[";
            for (size_t i = 0; i < a.size() && i < 8; ++i) out += (i ? ", " : "") + formatNumber(a[i]);
            return out + (a.size() > 8 ? ", ...]" : "]");
        }
        std::string operator()(const Unusable& u) const { return "a value of type " + u.typeName; }
    };
    return std::visit(Visitor{}, value);
}

std::string Diagnostic::text() const {
    const char* s = severity == Severity::Error ? "error" : severity == Severity::Warning ? "warning" : "info";
    return std::string(s) + ": " + primPath + (attribute.empty() ? "" : "." + attribute) + ": " + message;
}

bool Diagnostics::hasErrors() const {
    for (const Diagnostic& d : list_)
        if (d.severity == Severity::Error) return true;
    return false;
}

}  // namespace volphoton::translate
