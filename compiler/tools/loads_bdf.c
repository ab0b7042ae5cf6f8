/* loads_bdf.c: the load export as Nastran bulk data.  The cards are those of
 * MSC/NX Nastran's Quick Reference Guide for a transient response (SOL
 * 109/112): TLOAD1 (SID, EXCITEID, DELAY, TYPE, TID) scales the static load
 * set EXCITEID (here one FORCE or MOMENT: SID, G, CID, F, N1 N2 N3) by the
 * table TID (TABLED1: XAXIS, YAXIS, then x, y pairs ended by ENDT); DLOAD
 * (SID, S, S1 L1, S2 L2, ...) sums them, chosen by DLOAD = 1 in case
 * control.  Integer cards in small-field (8 columns), the tables in large
 * field (16 columns: 10 significant digits); continuations marked
 * explicitly. */
#include "loads_bdf.h"

#include <stdlib.h>
#include <string.h>

enum { DLOAD_SID = 1, TLOAD_BASE = 100000, EXCITE_BASE = 200000, TABLE_BASE = 300000 };

/* a continuation mark, unique in the file: "+Cn" (small field) or "*Cn" (large) */
static void mark(char *buf, size_t n, char kind, int count) { snprintf(buf, n, "%cC%d", kind, count); }

int write_loads_bdf(FILE *out, const char *what, const bdf_load *loads, int nloads, int nrows, const double *t,
                    const double *f, const double A0[9]) {
  static const char *const comp[6] = {"Fx", "Fy", "Fz", "Mx", "My", "Mz"};
  int nch = 6 * nloads, nmark = 0, nused = 0;
  double *g = NULL; /* the loads in the FE model's axes */
  int *used = NULL;
  if (nch > 0 && nrows > 0) {
    g = calloc((size_t)nrows * (size_t)nch, sizeof *g);
    used = calloc((size_t)nch, sizeof *used);
    if (!g || !used) { free(g); free(used); return -1; }
  }
  for (int i = 0; i < nrows; i++)
    for (int k = 0; k < nloads; k++)
      for (int h = 0; h < 2; h++) {
        const double *b = f + ((size_t)i * nloads + k) * 6 + 3 * h;
        double *o = g + ((size_t)i * nloads + k) * 6 + 3 * h;
        for (int r = 0; r < 3; r++) {
          o[r] = A0[3 * r] * b[0] + A0[3 * r + 1] * b[1] + A0[3 * r + 2] * b[2];
          if (o[r] != 0) used[6 * k + 3 * h + r] = 1;
        }
      }
  for (int c = 0; c < nch; c++) nused += used[c];
  fprintf(out, "$ mbcc load export: %s\n", what);
  fprintf(out, "$ %d load channel%s (of %d loads x 6 components; the ones zero at every time left out), "
               "%d times\n", nused, nused == 1 ? "" : "s", nloads, nrows);
  fputs("$ a transient dynamic load: DLOAD = 1 in case control (SOL 109/112); forces N, moments N m,\n"
        "$ time s, components along the basic axes of the FE model (CID 0) as the body carries them\n"
        "BEGIN BULK\n", out);
  /* DLOAD: SID, S, then (Si, Li) pairs, 3 on the first line and 4 on each next */
  char m0[16], m1[16];
  fprintf(out, "DLOAD   %8d%8s", DLOAD_SID, "1.0");
  int field = 3;
  for (int c = 0; c < nch; c++) {
    if (!used[c]) continue;
    if (field > 8) { /* the line's 8 fields are full: continue */
      mark(m0, sizeof m0, '+', ++nmark);
      fprintf(out, "%-8s\n%-8s", m0, m0);
      field = 1;
    }
    fprintf(out, "%8s%8d", "1.0", TLOAD_BASE + c + 1);
    field += 2;
  }
  fputc('\n', out);
  for (int c = 0; c < nch; c++) {
    if (!used[c]) continue;
    int k = c / 6, d = c % 6;
    fprintf(out, "$ %s at GRID %ld: %s\n", loads[k].name, loads[k].grid, comp[d]);
    double n[3] = {0, 0, 0};
    n[d % 3] = 1;
    fprintf(out, "%-8s%8d%8ld%8d%8s%8.1f%8.1f%8.1f\n", d < 3 ? "FORCE" : "MOMENT", EXCITE_BASE + c + 1,
            loads[k].grid, 0, "1.0", n[0], n[1], n[2]);
    fprintf(out, "TLOAD1  %8d%8d%8s%8d%8d\n", TLOAD_BASE + c + 1, EXCITE_BASE + c + 1, "", 0, TABLE_BASE + c + 1);
    /* TABLED1*: TID, LINEAR, LINEAR, then fields 5-8 blank, then x y pairs, ENDT */
    mark(m0, sizeof m0, '*', ++nmark);
    fprintf(out, "%-8s%16d%-16s%-16s%16s%-8s\n", "TABLED1*", TABLE_BASE + c + 1, "LINEAR", "LINEAR", "", m0);
    mark(m1, sizeof m1, '*', ++nmark);
    fprintf(out, "%-8s%16s%16s%16s%16s%-8s\n", m0, "", "", "", "", m1);
    int infield = 0; /* fields on the current large-field line (4 at most) */
    fprintf(out, "%-8s", m1);
    for (int i = 0; i <= nrows; i++) {
      for (int e = 0; e < (i < nrows ? 2 : 1); e++) {
        if (infield == 4) {
          mark(m1, sizeof m1, '*', ++nmark);
          fprintf(out, "%-8s\n%-8s", m1, m1);
          infield = 0;
        }
        if (i == nrows) fprintf(out, "%-16s", "ENDT");
        else fprintf(out, "%16.9E", e == 0 ? t[i] : g[(size_t)i * nch + c]);
        infield++;
      }
    }
    fputc('\n', out);
  }
  fputs("ENDDATA\n", out);
  free(g);
  free(used);
  return ferror(out) ? -1 : nused;
}
