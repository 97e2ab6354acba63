#include "bindings.hpp"

namespace gpilqg::python {

void bind_workflows(py::module_& m) { (void)m; }

}  // namespace gpilqg::python
