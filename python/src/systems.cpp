#include "bindings.hpp"

namespace gpilqg::python {

void bind_systems(py::module_& m) { (void)m; }

}  // namespace gpilqg::python
