/* gpilqg_policy.c: the control law of a gpilqg policy file (see gpilqg_policy.h). */
#include "gpilqg_policy.h"

static int is_finite(double v) { return v - v == 0.0; } /* false for NaN and +-infinity */

int gpilqg_policy_control(const gpilqg_policy* p, int t, const double* x, double* u) {
  int i, j;
  const double* x_bar;
  const double* gain;
  if (p == 0 || x == 0 || u == 0 || p->x_bar == 0 || p->u_bar == 0 || p->K == 0 || p->n <= 0 || p->m <= 0 ||
      p->horizon <= 0)
    return GPILQG_POLICY_BAD_ARGUMENT;
  if (t < 0 || t >= p->horizon) return GPILQG_POLICY_TIME_OUT_OF_RANGE;
  for (i = 0; i < p->n; ++i)
    if (!is_finite(x[i])) return GPILQG_POLICY_NON_FINITE_STATE;
  x_bar = p->x_bar + (long)t * p->n;
  for (j = 0; j < p->m; ++j) {
    double v = p->u_bar[(long)t * p->m + j];
    gain = p->K + ((long)t * p->m + j) * p->n;
    for (i = 0; i < p->n; ++i) v += (x[i] - x_bar[i]) * gain[i];
    if (p->u_min != 0 && v < p->u_min[j]) v = p->u_min[j];
    if (p->u_max != 0 && v > p->u_max[j]) v = p->u_max[j];
    u[j] = v;
  }
  return GPILQG_POLICY_OK;
}
