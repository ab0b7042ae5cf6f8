/* mb_superelement.h: a massless FE model statically condensed to more than
 * two interface nodes (a superelement with n + 1 nodes; with two it is a
 * field, mb_field.h).  Node 0 is marker m0 (the element's frame); nodes 1..n
 * are the n consecutive markers m1, m1 + 1, ...  The condensed stiffness is
 * that of nodes 1..n with node 0 held: the FE model's free-free stiffness is
 * singular (rigid-body motion), and the element works on the motion of each
 * node relative to node 0, which rigid-body motion leaves at zero.
 *
 * Parameters (m->force_prm + padr, 1 + 3 n + 72 n^2 reals):
 *   MB_SUPER_N        n, the nodes beside node 0 (a whole number)
 *   MB_SUPER_D0 ..    d0[3 n]: undeformed offsets of nodes 1..n from node 0, marker 0's axes
 *   then K[(6n)^2]:   stiffness, row-major, node by node [translation; rotation]
 *   then C[(6n)^2]:   damping, row-major
 * No laws, no state. */
#ifndef MB_SUPERELEMENT_H
#define MB_SUPERELEMENT_H

#include "mb_field.h"

enum { MB_SUPER_N = 0, MB_SUPER_D0 = 1, MB_SUPER_MAX_NODES = 16 /* n at most */ };

static inline int mb_superelement_nprm(int n) { return 1 + 3 * n + 72 * n * n; }

/* With u_k, ud_k node k's displacement and rate relative to node 0 in marker
 * 0's axes (as a field's: mb_field_relative) stacked into u, ud (6 n), the
 * force F[3k..] and torque T[3k..] on node k (k = 0..n-1 for nodes 1..n) at
 * its point are R0 (-K u - C ud) of its rows; the reaction of each acts on
 * node 0's body at that same point.  Returns 1/2 u^T K u. */
#ifdef MB_NO_SUPERELEMENT
/* An embedded package of a model without superelements defines
 * MB_NO_SUPERELEMENT (in its mb_types.h): the element is left out of its
 * flash.  A superelement reaching it gives NaN, which the step reports
 * (MB_ERR_NONFINITE). */
static inline mb_real mb_superelement(const mb_marker *m0, const mb_marker *const *mk, const mb_real *prm,
                                      mb_real *F, mb_real *T) {
  (void)m0, (void)mk;
  for (int k = 0; k < 3 * (int)prm[MB_SUPER_N]; k++) F[k] = T[k] = (mb_real)NAN;
  return (mb_real)NAN;
}
#else
static inline mb_real mb_superelement(const mb_marker *m0, const mb_marker *const *mk, const mb_real *prm,
                                      mb_real *F, mb_real *T) {
  int n = (int)prm[MB_SUPER_N], nd = 6 * n;
  const mb_real *K = prm + MB_SUPER_D0 + 3 * n, *C = K + nd * nd;
  mb_real u[6 * MB_SUPER_MAX_NODES], ud[6 * MB_SUPER_MAX_NODES];
  for (int k = 0; k < n; k++) mb_field_relative(m0, mk[k], prm + MB_SUPER_D0 + 3 * k, u + 6 * k, ud + 6 * k);
  mb_real E = 0;
  for (int k = 0; k < n; k++) {
    mb_real f[6];
    for (int i = 0; i < 6; i++) {
      const mb_real *Ki = K + nd * (6 * k + i), *Ci = C + nd * (6 * k + i); /* nd <= 96: int is enough */
      mb_real s = 0, e = 0;
      for (int j = 0; j < nd; j++) {
        s += Ki[j] * u[j] + Ci[j] * ud[j];
        e += Ki[j] * u[j];
      }
      f[i] = -s;
      E += MB_R(0.5) * u[6 * k + i] * e;
    }
    mb_mul3(m0->R, f, F + 3 * k);
    mb_mul3(m0->R, f + 3, T + 3 * k);
  }
  return E;
}

#endif /* MB_NO_SUPERELEMENT */

#endif
