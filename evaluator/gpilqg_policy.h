/* gpilqg_policy.h: run a gpilqg policy file on a robot's controller, in plain C (C89 and later).
 *
 * No dependencies, no allocation, no global state: the caller owns the arrays. They are the datasets of
 * the policy file (docs/formats.md#policy-file-gpilqg-plan---out-policyh5) in the order HDF5 stores
 * them (row-major):
 *
 *   x_bar  (T+1) x n   the planned nominal states            x_bar[t*n + i]
 *   u_bar  T x m       the nominal controls                  u_bar[t*m + j]
 *   K      T x m x n   the feedback gains                    K[(t*m + j)*n + i]
 *   u_min, u_max  m    the attributes of the same names, or NULL when the file has none
 *
 * The control law at step t with the measured state x:
 *     u = clamp(u_bar_t + K_t (x - x_bar_t), u_min, u_max).
 * Compile gpilqg_policy.c with the controller's code; the C++ header gpilqg_policy.hpp does the same
 * with owned storage.
 */
#ifndef GPILQG_POLICY_H
#define GPILQG_POLICY_H

#ifdef __cplusplus
extern "C" {
#endif

typedef struct gpilqg_policy {
  int horizon; /* T: steps with a control */
  int n;       /* states */
  int m;       /* controls */
  const double* x_bar;
  const double* u_bar;
  const double* K;
  const double* u_min; /* may be NULL */
  const double* u_max; /* may be NULL */
} gpilqg_policy;

/* Return values of gpilqg_policy_control. */
enum {
  GPILQG_POLICY_OK = 0,
  GPILQG_POLICY_BAD_ARGUMENT = -1,     /* a NULL pointer or a non-positive size */
  GPILQG_POLICY_TIME_OUT_OF_RANGE = -2, /* t < 0 or t >= horizon: the plan has no control there */
  GPILQG_POLICY_NON_FINITE_STATE = -3   /* x holds a NaN or an infinity */
};

/* Writes the control of step t for the measured state x (n entries) into u (m entries) and returns
 * GPILQG_POLICY_OK; on any other return value u is left untouched. */
int gpilqg_policy_control(const gpilqg_policy* policy, int t, const double* x, double* u);

#ifdef __cplusplus
}
#endif

#endif /* GPILQG_POLICY_H */
