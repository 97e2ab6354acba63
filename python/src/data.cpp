#include "bindings.hpp"

namespace gpilqg::python {

void bind_data(py::module_& m) { (void)m; }

}  // namespace gpilqg::python
