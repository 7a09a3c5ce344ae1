// translation layer bindings (lead)
#include "bindings.h"

namespace volphoton::bindings {

void bindTranslate(pybind11::module_& m) { (void)m; }

}  // namespace volphoton::bindings
