#include "bindings.hpp"

namespace gpilqg::python {

void bind_gp(py::module_& m) { (void)m; }

}  // namespace gpilqg::python
