#include "core/diagnostics.h"

#include <iostream>
#include <mutex>

namespace volphoton {
namespace {
std::mutex& sinkMutex() {
    static std::mutex m;
    return m;
}
DiagnosticSink& sink() {
    static DiagnosticSink s;
    return s;
}
}  // namespace

void setDiagnosticSink(DiagnosticSink s) {
    std::lock_guard<std::mutex> lock(sinkMutex());
    sink() = std::move(s);
}

void report(Severity severity, const std::string& message) {
    std::lock_guard<std::mutex> lock(sinkMutex());
    if (sink()) {
        sink()(severity, message);
        return;
    }
    const char* tag = severity == Severity::Error ? "error" : severity == Severity::Warning ? "warning" : "info";
    std::cerr << "volphoton " << tag << ": " << message << std::endl;
}

}  // namespace volphoton
