// volphoton-vdbprobe: loads the grids of one VDB file with the core's loader, in a process of its own,
// for the guard in core/vdbGuard.h (which runs it and reads its end, never its output).
//
//   volphoton-vdbprobe FILE DENSITY_GRID [--temperature NAME] [--emission NAME] [--albedo NAME]
//                      [--max-voxels N]
//
// | exit            | meaning                                                                     |
// |-----------------|-----------------------------------------------------------------------------|
// | 0               | the grids loaded, or loadGridMedium refused the file with an exception       |
// |                 | (the host's own load reports that with its message)                         |
// | 2               | bad command line                                                             |
// | killed / hangs  | what the guard is for: a signal or the guard's time-out names the file bad   |
//
// It prints nothing the guard reads; with -v it prints the loader's message (by hand, for debugging).
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <exception>
#include <string>

#include "core/diagnostics.h"
#include "core/gridMedium.h"

namespace {

int usage() {
    std::fprintf(stderr,
                 "usage: volphoton-vdbprobe FILE DENSITY_GRID [--temperature NAME] [--emission NAME] "
                 "[--albedo NAME] [--max-voxels N] [-v]\n");
    return 2;
}

}  // namespace

int main(int argc, char** argv) {
    using namespace volphoton;
    GridMediumDesc desc;
    bool verbose = false;
    int positional = 0;
    for (int i = 1; i < argc; ++i) {
        std::string a = argv[i];
        auto value = [&](std::string& target) {
            if (i + 1 >= argc) return false;
            target = argv[++i];
            return true;
        };
        if (a == "-v") {
            verbose = true;
        } else if (a == "--temperature") {
            if (!value(desc.temperatureGrid)) return usage();
        } else if (a == "--emission") {
            if (!value(desc.emissionGrid)) return usage();
        } else if (a == "--albedo") {
            if (!value(desc.albedoGrid)) return usage();
        } else if (a == "--max-voxels") {
            std::string n;
            if (!value(n) || n.empty() || n.find_first_not_of("0123456789") != std::string::npos) return usage();
            desc.maxActiveVoxels = std::stoull(n);
        } else if (positional == 0) {
            desc.filePath = a;
            ++positional;
        } else if (positional == 1) {
            desc.densityGrid = a;
            ++positional;
        } else {
            return usage();
        }
    }
    if (positional != 2) return usage();
    if (!verbose) setDiagnosticSink([](Severity, const std::string&) {});
    try {
        loadGridMedium(desc);
        if (verbose) std::printf("loaded %s\n", desc.filePath.c_str());
    } catch (const std::exception& e) {
        if (verbose) std::printf("refused cleanly: %s\n", e.what());
    }
    return 0;
}
