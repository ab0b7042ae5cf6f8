/* import_mtx.c: a flexible body's FE model from exported matrices: Matrix
 * Market stiffness and mass (coordinate, real or integer, symmetric or
 * general), a DOF map (matrix row -> node id, DOF) and the node positions.
 * Formats: docs/model-format.md, "FE files". */
#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "diag.h"
#include "yaml_map.h"
#include "fe_import.h"

typedef struct {
  const char *path;
  FILE *f;
  int line;
  char buf[1024];
  int errors;
} text_file;

/* the reader's allocator: out of memory unwinds to ir_read, which reports it */
static void *mtx_alloc(size_t n, size_t size) { return xcalloc(n ? n : 1, size); }

#if defined(__GNUC__) || defined(__clang__)
__attribute__((format(printf, 3, 4)))
#endif
static void tf_error(text_file *t, int col, const char *fmt, ...) {
  va_list ap;
  va_start(ap, fmt);
  diag_verror(t->path, (ir_loc){t->line, col}, fmt, ap);
  va_end(ap);
  t->errors++;
}

static int tf_open(text_file *t, const char *path) {
  memset(t, 0, sizeof *t);
  t->path = path;
  t->f = fopen(path, "r");
  if (!t->f) {
    diag_error(NULL, (ir_loc){0, 0}, "cannot open FE file '%s': %s", path, strerror(errno));
    return -1;
  }
  return 0;
}

/* the next line that is not blank or a comment ('%' in Matrix Market, '#' or
 * '!' in the maps); 0 at the end */
static int tf_next(text_file *t, const char *comments) {
  while (fgets(t->buf, sizeof t->buf, t->f)) {
    t->line++;
    t->buf[strcspn(t->buf, "\r\n")] = 0;
    const char *s = t->buf;
    while (isspace((unsigned char)*s)) s++;
    if (!*s || strchr(comments, *s)) continue;
    return 1;
  }
  return 0;
}

/* split the line at commas, semicolons and white space: up to max tokens,
 * their columns in col; returns the count */
static int tf_tokens(text_file *t, char **tok, int *col, int max) {
  int n = 0;
  char *s = t->buf;
  while (*s) {
    while (*s && (isspace((unsigned char)*s) || *s == ',' || *s == ';')) s++;
    if (!*s) break;
    if (n == max) return max + 1;
    tok[n] = s;
    col[n++] = (int)(s - t->buf) + 1;
    while (*s && !isspace((unsigned char)*s) && *s != ',' && *s != ';') s++;
    if (*s) *s++ = 0;
  }
  return n;
}

static int to_long(const char *s, long *v) {
  char *end;
  errno = 0;
  *v = strtol(s, &end, 10);
  return *s && !*end && !errno;
}
static int to_real(const char *s, double *v) {
  char *end;
  errno = 0;
  *v = strtod(s, &end);
  return *s && !*end && !errno && isfinite(*v);
}

/* a DOF: 1..6 or a name (UX UY UZ, ROTX/RX, ROTY/RY, ROTZ/RZ) */
static int to_dof(const char *s) {
  static const char *const names[][3] = {{"UX", "X", "TX"},    {"UY", "Y", "TY"},    {"UZ", "Z", "TZ"},
                                         {"ROTX", "RX", "RX"}, {"ROTY", "RY", "RY"}, {"ROTZ", "RZ", "RZ"}};
  long v;
  if (to_long(s, &v)) return v >= 1 && v <= 6 ? (int)v - 1 : -1;
  char up[8];
  size_t n = strlen(s);
  if (n >= sizeof up) return -1;
  for (size_t i = 0; i <= n; i++) up[i] = (char)toupper((unsigned char)s[i]);
  for (int d = 0; d < 6; d++)
    for (int k = 0; k < 3; k++)
      if (!strcmp(up, names[d][k])) return d;
  return -1;
}

/* a Matrix Market coordinate matrix, n x n, as 0-based triplets (both
 * triangles); symmetric files give one triangle, general ones are checked
 * for symmetry */
static int read_mtx(const char *path, int *n_out, ir_fe_matrix *out) {
  text_file t;
  if (tf_open(&t, path)) return -1;
  int rc = -1, symmetric = 0;
  long nr = 0, nc = 0, nnz = 0;
  if (!fgets(t.buf, sizeof t.buf, t.f)) {
    diag_error(path, (ir_loc){1, 1}, "empty file (expected a Matrix Market header)");
    goto done;
  }
  t.line = 1;
  {
    char *tok[8];
    int col[8];
    t.buf[strcspn(t.buf, "\r\n")] = 0;
    int k = tf_tokens(&t, tok, col, 6);
    for (int i = 0; i < k && i < 6; i++)
      for (char *p = tok[i]; *p; p++) *p = (char)tolower((unsigned char)*p);
    if (k != 5 || strcmp(tok[0], "%%matrixmarket") || strcmp(tok[1], "matrix")) {
      tf_error(&t, 1, "expected '%%%%MatrixMarket matrix coordinate real symmetric' (or general)");
      goto done;
    }
    if (strcmp(tok[2], "coordinate")) {
      tf_error(&t, col[2], "only the coordinate format is read (got '%s')", tok[2]);
      goto done;
    }
    if (strcmp(tok[3], "real") && strcmp(tok[3], "integer")) {
      tf_error(&t, col[3], "the entries must be real (got '%s')", tok[3]);
      goto done;
    }
    if (!strcmp(tok[4], "symmetric")) symmetric = 1;
    else if (strcmp(tok[4], "general")) {
      tf_error(&t, col[4], "the matrix must be symmetric or general (got '%s')", tok[4]);
      goto done;
    }
  }
  if (!tf_next(&t, "%")) {
    tf_error(&t, 1, "missing the size line (rows columns entries)");
    goto done;
  }
  {
    char *tok[4];
    int col[4];
    if (tf_tokens(&t, tok, col, 3) != 3 || !to_long(tok[0], &nr) || !to_long(tok[1], &nc) ||
        !to_long(tok[2], &nnz) || nr < 1 || nr != nc || nnz < 0 || nr > 100000000 || nnz > 1000000000) {
      tf_error(&t, 1, "expected the size line 'n n entries' of a square matrix");
      goto done;
    }
  }
  out->row = mtx_alloc((size_t)nnz * (symmetric ? 2 : 1), sizeof *out->row);
  out->col = mtx_alloc((size_t)nnz * (symmetric ? 2 : 1), sizeof *out->col);
  out->val = mtx_alloc((size_t)nnz * (symmetric ? 2 : 1), sizeof *out->val);
  out->nnz = 0;
  for (long e = 0; e < nnz; e++) {
    if (!tf_next(&t, "%")) {
      tf_error(&t, 1, "the file ends after %ld of its %ld entries", e, nnz);
      goto done;
    }
    char *tok[4];
    int col[4];
    long i, j;
    double v;
    if (tf_tokens(&t, tok, col, 3) != 3) {
      tf_error(&t, 1, "expected an entry 'row column value'");
      goto done;
    }
    if (!to_long(tok[0], &i) || !to_long(tok[1], &j) || i < 1 || j < 1 || i > nr || j > nr) {
      tf_error(&t, col[0], "entry (%s, %s) is outside the %ld x %ld matrix", tok[0], tok[1], nr, nr);
      goto done;
    }
    if (!to_real(tok[2], &v)) {
      tf_error(&t, col[2], "'%s' is not a finite number", tok[2]);
      goto done;
    }
    if (symmetric && j > i) {
      tf_error(&t, col[0], "a symmetric Matrix Market file holds the lower triangle (row >= column; got "
               "(%ld, %ld))", i, j);
      goto done;
    }
    out->row[out->nnz] = (int)i - 1;
    out->col[out->nnz] = (int)j - 1;
    out->val[out->nnz++] = v;
    if (symmetric && i != j) {
      out->row[out->nnz] = (int)j - 1;
      out->col[out->nnz] = (int)i - 1;
      out->val[out->nnz++] = v;
    }
  }
  if (tf_next(&t, "%")) {
    tf_error(&t, 1, "more entries than the %ld the size line announces", nnz);
    goto done;
  }
  *n_out = (int)nr;
  rc = 0;
done:
  fclose(t.f);
  if (rc) {
    free(out->row); free(out->col); free(out->val);
    memset(out, 0, sizeof *out);
  }
  return rc;
}

/* a general matrix must be symmetric (to 1e-9 of its largest entry): each
 * entry above the diagonal less its mirror, summed by sorting (no dense copy) */
typedef struct {
  long long key;
  double v;
} mtx_term;

static int cmp_term(const void *a, const void *b) {
  long long x = ((const mtx_term *)a)->key, y = ((const mtx_term *)b)->key;
  return (x > y) - (x < y);
}

static int check_symmetric(const char *path, int n, const ir_fe_matrix *m) {
  mtx_term *t = malloc(((size_t)m->nnz + 1) * sizeof *t);
  if (!t) { diag_error(path, (ir_loc){0, 0}, "out of memory"); return -1; }
  size_t k = 0;
  double big = 0;
  for (int e = 0; e < m->nnz; e++) {
    int i = m->row[e], j = m->col[e];
    big = fmax(big, fabs(m->val[e]));
    if (i == j) continue;
    t[k].key = i < j ? (long long)i * n + j : (long long)j * n + i;
    t[k++].v = i < j ? m->val[e] : -m->val[e];
  }
  qsort(t, k, sizeof *t, cmp_term);
  int rc = 0;
  for (size_t a = 0; a < k && !rc;) {
    size_t b = a;
    double sum = 0;
    while (b < k && t[b].key == t[a].key) sum += t[b++].v;
    if (fabs(sum) > 1e-9 * big) {
      int i = (int)(t[a].key / n), j = (int)(t[a].key % n);
      diag_error(path, (ir_loc){0, 0}, "the matrix is not symmetric: entries (%d, %d) and (%d, %d) differ",
                 i + 1, j + 1, j + 1, i + 1);
      rc = -1;
    }
    a = b;
  }
  free(t);
  return rc;
}

int fe_import_mtx(const fe_mtx_files *files, ir_flex *fx, double **global) {
  int errors_before = diag_errors();
  ir_fe_matrix K = {0, NULL, NULL, NULL}, M = {0, NULL, NULL, NULL};
  int nK = 0, nM = 0, nnodes = 0, cap = 0;
  long *ids = NULL;
  double *x = NULL;
  int *row_dof = NULL;
  unsigned char *present = NULL;
  text_file t;
  memset(&t, 0, sizeof t);
  if (read_mtx(files->stiffness, &nK, &K) || read_mtx(files->mass, &nM, &M)) goto done;
  if (nK != nM) {
    diag_error(files->mass, (ir_loc){0, 0}, "the mass matrix has %d rows, the stiffness matrix %d", nM, nK);
    goto done;
  }
  if (check_symmetric(files->stiffness, nK, &K) || check_symmetric(files->mass, nM, &M)) goto done;

  /* nodes: id x y z */
  if (tf_open(&t, files->nodes)) goto done;
  int header = 1;
  while (tf_next(&t, "#!%")) {
    char *tok[5];
    int col[5];
    long id;
    double p[3];
    int k = tf_tokens(&t, tok, col, 4);
    if (header && k > 0 && !to_long(tok[0], &id)) { header = 0; continue; } /* a header line */
    header = 0;
    if (k != 4 || !to_long(tok[0], &id) || !to_real(tok[1], &p[0]) || !to_real(tok[2], &p[1]) ||
        !to_real(tok[3], &p[2])) {
      tf_error(&t, 1, "expected a node 'id, x, y, z'");
      break;
    }
    for (int i = 0; i < nnodes; i++)
      if (ids[i] == id) { tf_error(&t, col[0], "node %ld is given twice", id); break; }
    if (t.errors) break;
    if (nnodes == cap) {
      cap = cap ? 2 * cap : 64;
      long *ni = realloc(ids, (size_t)cap * sizeof *ni);
      double *nx = realloc(x, 3 * (size_t)cap * sizeof *nx);
      if (!ni || !nx) out_of_memory();
      ids = ni;
      x = nx;
    }
    ids[nnodes] = id;
    memcpy(x + 3 * nnodes, p, sizeof p);
    nnodes++;
  }
  fclose(t.f);
  t.f = NULL;
  if (t.errors) goto done;
  if (nnodes < 2) {
    diag_error(files->nodes, (ir_loc){0, 0}, "the node file has %d nodes (at least 2 needed)", nnodes);
    goto done;
  }

  /* DOF map: one line per matrix row, in order: [row] node dof */
  row_dof = mtx_alloc((size_t)nK, sizeof *row_dof);
  present = mtx_alloc(6 * (size_t)nnodes, 1);
  if (tf_open(&t, files->dofs)) goto done;
  int rows = 0;
  header = 1;
  while (tf_next(&t, "#!%")) {
    char *tok[4];
    int col[4];
    long v, node;
    int k = tf_tokens(&t, tok, col, 3);
    if (header && k > 0 && !to_long(tok[0], &v)) { header = 0; continue; }
    header = 0;
    if (k != 2 && k != 3) {
      tf_error(&t, 1, "expected '[row] node dof' (e.g. '7, 12, UY')");
      break;
    }
    if (k == 3 && (!to_long(tok[0], &v) || v != rows + 1)) {
      tf_error(&t, col[0], "rows must be listed in order: expected row %d (got '%s')", rows + 1, tok[0]);
      break;
    }
    if (rows == nK) {
      tf_error(&t, 1, "more rows than the %d of the matrices", nK);
      break;
    }
    int in = k - 2, idx = -1, dof;
    if (!to_long(tok[in], &node)) { tf_error(&t, col[in], "'%s' is not a node id", tok[in]); break; }
    for (int i = 0; i < nnodes; i++)
      if (ids[i] == node) idx = i;
    if (idx < 0) { tf_error(&t, col[in], "node %ld is not in the node file", node); break; }
    if ((dof = to_dof(tok[in + 1])) < 0) {
      tf_error(&t, col[in + 1], "'%s' is not a DOF (1 to 6, or UX UY UZ ROTX ROTY ROTZ)", tok[in + 1]);
      break;
    }
    if (present[6 * idx + dof]) {
      tf_error(&t, col[in], "node %ld DOF %s appears twice", node, tok[in + 1]);
      break;
    }
    present[6 * idx + dof] = 1;
    row_dof[rows++] = 6 * idx + dof;
  }
  fclose(t.f);
  t.f = NULL;
  if (t.errors) goto done;
  if (rows != nK) {
    diag_error(files->dofs, (ir_loc){t.line, 1}, "the map lists %d rows, the matrices have %d", rows, nK);
    goto done;
  }
  ir_fe_matrix *G[2] = {&K, &M};
  for (int g = 0; g < 2; g++)
    for (int e = 0; e < G[g]->nnz; e++) {
      G[g]->row[e] = row_dof[G[g]->row[e]];
      G[g]->col[e] = row_dof[G[g]->col[e]];
    }
  fx->nnodes = nnodes;
  fx->node_ids = ids;
  ids = NULL;
  fx->K_given = mtx_alloc(1, sizeof *fx->K_given);
  fx->M_given = mtx_alloc(1, sizeof *fx->M_given);
  *fx->K_given = K;
  *fx->M_given = M;
  memset(&K, 0, sizeof K);
  memset(&M, 0, sizeof M);
  /* DOFs the export does not have do not move */
  for (int i = 0; i < 6 * nnodes; i++) present[i] = !present[i];
  fx->fixed = present;
  present = NULL;
  fx->mass = MASS_CONSISTENT;
  fx->fe_path = mtx_alloc(strlen(files->stiffness) + 1, 1);
  strcpy(fx->fe_path, files->stiffness);
  *global = x;
  x = NULL;
done:
  if (t.f) fclose(t.f);
  free(K.row); free(K.col); free(K.val);
  free(M.row); free(M.col); free(M.val);
  free(ids); free(x); free(row_dof); free(present);
  return diag_errors() > errors_before ? 2 : 0;
}
