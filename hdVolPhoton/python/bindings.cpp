// volphoton._core: pybind11 bindings of the renderer core for the usd-core front end (volphoton.cli).
//
// Conventions (see converters.h): vectors and colours are 3-tuples (any 3-sequence is accepted, a
// colour also takes one number), transforms are (4, 4) float64 arrays in the core's column-vector
// convention, bounds are ((lo), (hi)) tuples or None for "infinite", images are numpy float32 arrays
// (H, W, 3) or (H, W) with row 0 at the top. C++ std::invalid_argument -> ValueError,
// std::runtime_error -> RuntimeError (message unchanged).
//
// Threads: every call that may run TBB work (Scene, Renderer, render, render_pass, load_grid_medium,
// GridMedium statistics aside) releases the GIL. Python callbacks (progress, cancel, the diagnostic
// sink) re-acquire it; an exception raised in one cancels the render and is re-raised by render().
// Ctrl-C (SIGINT) is polled from the main thread during render() and cancels it with
// KeyboardInterrupt.
//
// This file is the module entry point only: each topic registers itself (bindings.h lists them).
#include "bindings.h"

PYBIND11_MODULE(_core, m) {
    m.doc() = "volphoton renderer core (C++), for the usd-core front end. See volphoton/__init__.py.";
#ifdef VOLPHOTON_VERSION
    m.attr("__version__") = VOLPHOTON_VERSION;
#endif
#ifdef VOLPHOTON_NO_VOLUMES
    m.attr("NO_VOLUMES") = true;
#else
    m.attr("NO_VOLUMES") = false;
#endif
    using namespace volphoton::bindings;
    bindMedia(m);
    bindScene(m);
    bindRender(m);
    bindImage(m);
    bindVdbTestHelpers(m);
    bindGltf(m);
    bindTranslate(m);
    bindVdbGuard(m);
}
