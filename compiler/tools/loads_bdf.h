/* loads_bdf.h: load time histories as Nastran bulk data (mbcc run --loads FILE.bdf) */
#ifndef MBCC_LOADS_BDF_H
#define MBCC_LOADS_BDF_H

#include <stdio.h>

/* One load on a node: its GRID id and a name for the comments. */
typedef struct {
  long grid;
  const char *name;
} bdf_load;

/* Write nloads loads over nrows times t[] as a transient dynamic load for
 * a Nastran deck: per channel (load k, component c of Fx Fy Fz Mx My Mz)
 * that is not zero at every time, a FORCE or MOMENT of unit size along a
 * basic axis (CID 0), a TABLED1 of its value over time and a TLOAD1 tying
 * them; one DLOAD (SID 1) sums the TLOAD1s.  f: nrows x nloads x 6, in the
 * body's axes; A0 (row-major, columns the body axes at t = 0 in the FE
 * model's input axes) turns them into those axes.  'what' is written as a
 * comment.  Returns the number of channels written, or -1 on a write error. */
int write_loads_bdf(FILE *out, const char *what, const bdf_load *loads, int nloads, int nrows, const double *t,
                    const double *f, const double A0[9]);

#endif
