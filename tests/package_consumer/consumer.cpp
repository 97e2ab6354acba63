// Builds against the installed headers and libraries and checks one step of the reference cart-pole.
#include <cmath>
#include <cstdio>

#include "gpilqg/core/integrator.hpp"
#include "gpilqg/core/systems.hpp"

int main() {
  gpilqg::IntegratedStepModel model(gpilqg::make_system("cartpole"), gpilqg::Integrator::Euler, 0.05);
  gpilqg::Vector x(4), u(1);
  x << 0.3, -0.2, 2.0, 0.7;
  u << 1.3;
  const gpilqg::Vector next = model.next(x, u);
  // tests/reference/ilqr_cartpole/README.md: x+[1] = -0.25382463930283294
  const bool ok = std::abs(next(1) + 0.25382463930283294) < 1e-12;
  std::printf("consumer: x+[1] = %.17g %s\n", next(1), ok ? "ok" : "WRONG");
  return ok ? 0 : 1;
}
