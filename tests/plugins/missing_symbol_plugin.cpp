// A plugin that needs something this gpilqg does not have, as one built against another version may:
// a variable read at load time, so dlopen itself fails with "undefined symbol".
#include "gpilqg/core/plugin.hpp"

namespace gpilqg {
extern const int kOnlyInAnotherVersion;  // defined nowhere
}  // namespace gpilqg

const int* const g_needed = &gpilqg::kOnlyInAnotherVersion;

GPILQG_PLUGIN(registrar) {
  if (*g_needed != 0) registrar.add({});
}
