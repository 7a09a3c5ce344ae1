// Where the core reports problems it recovers from (clamped voxels, clamped parameters). Front ends
// install a sink: the Python CLI prints, the Hydra delegate forwards to TF_WARN. Messages name the
// offending object (grid name, file, parameter) so users can find it.
#pragma once

#include <functional>
#include <string>

namespace volphoton {

enum class Severity { Info, Warning, Error };

using DiagnosticSink = std::function<void(Severity, const std::string&)>;

/// Installs the process-wide sink; the default writes to stderr. Thread-safe.
void setDiagnosticSink(DiagnosticSink sink);
void report(Severity severity, const std::string& message);
inline void warn(const std::string& message) { report(Severity::Warning, message); }
/// `s` in single quotes: how a message names a file, grid or prim.
inline std::string quote(const std::string& s) { return "'" + s + "'"; }

}  // namespace volphoton
