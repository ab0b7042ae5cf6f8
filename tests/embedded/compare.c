/* compare.c: compares two output logs of an embedded package, row by row:
 *   compare A B [FLOOR]
 * A log is either verify_main's (each value the hex of its float or double
 * bits, time first) or a CSV of mbcc run (header skipped).  Prints the largest
 * error of a column relative to that column's largest magnitude in B (so a
 * column that crosses zero is judged against its size, not against zero) and
 * the column; a column of round-off only (largest magnitude below FLOOR, default
 * 1e-9, of the table's largest: an out-of-plane force of 1e-36 N, the total
 * energy of a conservative model, 0) is judged against that FLOOR; a float
 * against double comparison takes 1e-3, the system's scale.  Exit 1 if the row counts differ or a value is not finite. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define MAXROWS 4096
#define MAXCOLS 64

typedef struct { int rows, cols; double v[MAXROWS][MAXCOLS]; } table;

static double hex_value(const char *t, size_t n) {
  uint64_t bits = strtoull(t, NULL, 16);
  if (n == 8) { uint32_t b = (uint32_t)bits; float f; memcpy(&f, &b, sizeof f); return f; }
  double d;
  memcpy(&d, &bits, sizeof d);
  return d;
}

static int read_table(const char *path, table *T) {
  FILE *f = fopen(path, "r");
  if (!f) { fprintf(stderr, "compare: cannot read %s\n", path); return 1; }
  char line[16384];
  T->rows = 0;
  T->cols = 0;
  while (fgets(line, sizeof line, f) && T->rows < MAXROWS) {
    int csv = strchr(line, ',') != NULL, c = 0;
    if (!strncmp(line, "status", 6) || !(line[0] == '-' || line[0] == '.' || (line[0] >= '0' && line[0] <= '9'))) continue;
    for (char *tok = strtok(line, csv ? ",\n" : " \n"); tok && c < MAXCOLS; tok = strtok(NULL, csv ? ",\n" : " \n"))
      T->v[T->rows][c++] = csv ? strtod(tok, NULL) : hex_value(tok, strlen(tok));
    if (T->cols == 0) T->cols = c;
    T->rows++;
  }
  fclose(f);
  return 0;
}

int main(int argc, char **argv) {
  static table A, B;
  if (argc < 3 || read_table(argv[1], &A) || read_table(argv[2], &B)) return 2;
  int cols = A.cols < B.cols ? A.cols : B.cols;
  double floor_rel = argc > 3 ? atof(argv[3]) : 1e-9;
  if (A.rows != B.rows || A.rows == 0) {
    printf("rows differ: %d and %d\n", A.rows, B.rows);
    return 1;
  }
  double worst = 0, table_max = 0;
  int worst_col = -1;
  for (int c = 0; c < cols; c++)
    for (int r = 0; r < B.rows; r++) table_max = fmax(table_max, fabs(B.v[r][c]));
  for (int c = 0; c < cols; c++) {
    double scale = floor_rel * table_max, err = 0;
    for (int r = 0; r < B.rows; r++) scale = fmax(scale, fabs(B.v[r][c]));
    for (int r = 0; r < A.rows; r++) {
      if (!isfinite(A.v[r][c]) || !isfinite(B.v[r][c])) { printf("non-finite value, row %d column %d\n", r, c); return 1; }
      err = fmax(err, fabs(A.v[r][c] - B.v[r][c]));
    }
    double rel = scale > 0 ? err / scale : err;
    if (getenv("COMPARE_VERBOSE")) printf("column %d: error %.3g of %.3g\n", c, err, scale);
    if (rel > worst || worst_col < 0) { worst = rel; worst_col = c; }
  }
  printf("%.3g %d %d\n", worst, worst_col, A.rows);
  return 0;
}
