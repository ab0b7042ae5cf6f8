/* modal_file.c: a flexible body's modal data file (modal_file:,
 * docs/modal-file.md) read into the IR (ir_modal_data) with the reader's YAML
 * layer (yaml_map.h): the nodes and every mode, each checked where it is
 * written (file:line:col in the modal file, then a note at the model's
 * 'modal_file'), the shapes' orthonormality included.  The flexible-body
 * stage (compiler/flex/fe.c) only selects among the modes. */
#include "modal_file.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bounds.h"
#include "reader.h"

/* tolerance of X^T M X = I */
#define MODAL_NORM_TOL 1e-6

void free_modal_data(ir_modal_data *md) {
  if (md == NULL) return;
  free(md->position);
  free(md->mass);
  free(md->inertia);
  free(md->freq_hz);
  free(md->shapes);
  free(md);
}

/* 3 numbers (the diagonal) or 9 (the tensor, row-major) into J */
static bool read_inertia(reader *fr, yaml_node_t *n, int k, double J[9]) {
  char label[64];
  snprintf(label, sizeof label, "'inertia' of node %d", k);
  int length = n->type == YAML_SEQUENCE_NODE ? seq_length(n) : -1;
  if (length != 3 && length != 9) {
    char got[SHOWN_SIZE];
    if (length >= 0) snprintf(got, sizeof got, "%d", length);
    else snprintf(got, sizeof got, "%s", show_node(fr, n));
    error_at(fr, loc_of(n), "%s: expected a list of 3 numbers (the diagonal) or 9 (the tensor, row-major), got %s",
             label, got);
    return false;
  }
  double v[9];
  if (!to_vector(fr, n, label, length, v)) return false;
  memset(J, 0, 9 * sizeof *J);
  if (length == 3) J[0] = v[0], J[4] = v[1], J[8] = v[2];
  else memcpy(J, v, sizeof v);
  double big = 0;
  for (int i = 0; i < 9; i++) big = fmax(big, fabs(J[i]));
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < i; j++)
      if (fabs(J[3 * i + j] - J[3 * j + i]) > 1e-9 * big) {
        error_at(fr, loc_of(n), "%s is not symmetric (element %d is %g, element %d is %g)", label,
                 3 * i + j + 1, J[3 * i + j], 3 * j + i + 1, J[3 * j + i]);
        return false;
      }
  if (J[0] < 0 || J[4] < 0 || J[8] < 0) {
    error_at(fr, loc_of(n), "%s has a negative diagonal term", label);
    return false;
  }
  return true;
}

/* node k: its position, mass and inertia */
static void read_node(reader *fr, yaml_node_t *n, int k, ir_modal_data *md) {
  mapping nm;
  if (map_open(&nm, fr, n, loc_of(n), "node %d of the modal data file", k)) {
    static const char *const keys[] = {"position", "mass", "inertia", NULL};
    map_check_keys(&nm, keys);
    char label[64];
    yaml_node_t *position = map_require(&nm, "position", true, "a 3-vector");
    snprintf(label, sizeof label, "'position' of node %d", k);
    if (position) to_vector(fr, position, label, 3, md->position + 3 * k);
    yaml_node_t *mass = map_require(&nm, "mass", true, "a number");
    snprintf(label, sizeof label, "'mass' of node %d", k);
    if (mass && to_number(fr, mass, label, &md->mass[k]) && md->mass[k] < 0)
      error_at(fr, loc_of(mass), "%s must be >= 0 (got %g)", label, md->mass[k]);
    yaml_node_t *inertia = map_get(&nm, "inertia");
    if (inertia) read_inertia(fr, inertia, k, md->inertia + 9 * k);
  }
  map_close(&nm);
}

/* mode j's frequency (ascending after the previous one's); its shape node,
 * a list of one row per node, in *shape (NULL after an error) */
static void read_mode(reader *fr, yaml_node_t *n, int j, ir_modal_data *md, yaml_node_t **shape) {
  mapping mm;
  *shape = NULL;
  if (map_open(&mm, fr, n, loc_of(n), "mode %d of the modal data file", j + 1)) {
    static const char *const keys[] = {"frequency", "shape", NULL};
    map_check_keys(&mm, keys);
    char label[64];
    snprintf(label, sizeof label, "'frequency' of mode %d", j + 1);
    yaml_node_t *f = map_require(&mm, "frequency", true, "a number, Hz");
    double *hz = md->freq_hz + j;
    if (f && to_number(fr, f, label, hz)) {
      if (*hz < 0)
        error_at(fr, loc_of(f), "%s must be >= 0 (got %g Hz)", label, *hz);
      else if (j > 0 && *hz < hz[-1])
        error_at(fr, loc_of(f), "%s is below the previous mode's: the modes must be in ascending frequency "
                 "(%.17g Hz after %.17g Hz)", label, *hz, hz[-1]);
    }
    yaml_node_t *s = map_require(&mm, "shape", true, "a list of one row per node");
    if (s && (s->type != YAML_SEQUENCE_NODE || seq_length(s) != md->nnodes)) {
      char got[SHOWN_SIZE];
      if (s->type == YAML_SEQUENCE_NODE) snprintf(got, sizeof got, "%d", seq_length(s));
      else snprintf(got, sizeof got, "%s", show_node(fr, s));
      error_at(fr, loc_of(s), "'shape' of mode %d: expected a list of %d rows (one per node), got %s", j + 1,
               md->nnodes, got);
    } else {
      *shape = s;
    }
  }
  map_close(&mm);
}

/* X^T M X = I with the nodal masses and inertias (docs/modal-file.md: the
 * modal stiffness diag((2 pi f)^2) presumes it), at the mode at fault */
static bool check_orthonormal(reader *fr, const ir_modal_data *md, yaml_node_t *modes) {
  int nn = md->nnodes;
  for (int a = 0; a < md->nmodes; a++)
    for (int b = 0; b <= a; b++) {
      const double *xa = md->shapes + (size_t)a * 6 * nn, *xb = md->shapes + (size_t)b * 6 * nn;
      double g = 0;
      for (int k = 0; k < nn; k++) {
        const double *u = xa + 6 * k, *v = xb + 6 * k, *J = md->inertia + 9 * k;
        g += md->mass[k] * (u[0] * v[0] + u[1] * v[1] + u[2] * v[2]);
        for (int i = 0; i < 3; i++)
          for (int l = 0; l < 3; l++) g += u[3 + i] * J[3 * i + l] * v[3 + l];
      }
      ir_loc at = loc_of(seq_item(fr, modes, a));
      if (a == b && fabs(g - 1) > MODAL_NORM_TOL) {
        error_at(fr, at, "mode %d is not mass-normalized with respect to the nodal masses and inertias: "
                 "x^T M x = %.10g (expected 1 to %g)", a + 1, g, MODAL_NORM_TOL);
        return false;
      }
      if (a != b && fabs(g) > MODAL_NORM_TOL) {
        error_at(fr, at, "modes %d and %d are not orthogonal with respect to the nodal masses and inertias: "
                 "x%d^T M x%d = %.10g (expected 0 to %g)", b + 1, a + 1, b + 1, a + 1, g, MODAL_NORM_TOL);
        return false;
      }
    }
  return true;
}

/* the document of the modal data file into md; false after an error */
static bool read_content(reader *fr, ir_modal_data *md) {
  yaml_node_t *root = yaml_document_get_root_node(fr->doc);
  if (root == NULL) {
    error_at(fr, file_start, "empty modal data file (expected a mapping with 'format', 'nodes' and 'modes')");
    return false;
  }
  int errors = diag_errors();
  mapping top;
  yaml_node_t *format = NULL, *nodes = NULL, *modes = NULL;
  if (map_open(&top, fr, root, loc_of(root), "the modal data file")) {
    static const char *const keys[] = {"format", "description", "nodes", "modes", NULL};
    map_check_keys(&top, keys);
    format = map_require(&top, "format", true, "'" IR_MODAL_FORMAT "'");
    yaml_node_t *description = map_get(&top, "description");
    if (description && description->type != YAML_SCALAR_NODE)
      error_at(fr, loc_of(description), "'description' must be a string (got %s)", show_node(fr, description));
    nodes = map_require(&top, "nodes", true, "a list of nodes");
    modes = map_require(&top, "modes", true, "a list of modes");
  }
  map_close(&top);
  if (format && !scalar_equals(format, IR_MODAL_FORMAT)) {
    error_at(fr, loc_of(format), "unsupported format %s (expected '" IR_MODAL_FORMAT "')", show_node(fr, format));
    return false; /* another format: its content means something else */
  }
  if (nodes && (nodes->type != YAML_SEQUENCE_NODE || seq_length(nodes) == 0)) {
    error_at(fr, loc_of(nodes), "'nodes' must be a nonempty list of nodes (got %s)", show_node(fr, nodes));
    nodes = NULL;
  }
  if (modes && modes->type != YAML_SEQUENCE_NODE) {
    error_at(fr, loc_of(modes), "'modes' must be a list of modes (got %s)", show_node(fr, modes));
    modes = NULL;
  }
  if (!nodes || !modes) return false;

  int nn = md->nnodes = seq_length(nodes), nm = md->nmodes = seq_length(modes);
  md->position = xcalloc(3 * (size_t)nn, sizeof *md->position);
  md->mass = xcalloc((size_t)nn, sizeof *md->mass);
  md->inertia = xcalloc(9 * (size_t)nn, sizeof *md->inertia);
  md->freq_hz = xcalloc((size_t)nm, sizeof *md->freq_hz);
  for (int k = 0; k < nn; k++) read_node(fr, seq_item(fr, nodes, k), k, md);
  yaml_node_t **shape = xcalloc((size_t)nm, sizeof *shape);
  for (int j = 0; j < nm; j++) read_mode(fr, seq_item(fr, modes, j), j, md, &shape[j]);
  /* rows repeated by YAML aliases could make the shapes far larger than the
     file: every number must be written out */
  size_t written = (size_t)(fr->doc->nodes.top - fr->doc->nodes.start);
  if (diag_errors() == errors && 6.0 * nn * nm > (double)written) {
    error_at(fr, loc_of(modes), "the shapes of %d modes of %d nodes hold more numbers than the file (rows "
             "repeated by YAML aliases?): write every row out", nm, nn);
  }
  if (diag_errors() == errors) {
    md->shapes = xcalloc(6 * (size_t)nn * (size_t)nm, sizeof *md->shapes);
    for (int j = 0; j < nm; j++)
      for (int k = 0; k < nn; k++) {
        char label[96];
        snprintf(label, sizeof label, "the row of node %d (ux uy uz rx ry rz) in the 'shape' of mode %d", k, j + 1);
        to_vector(fr, seq_item(fr, shape[j], k), label, 6, md->shapes + (size_t)j * 6 * nn + 6 * k);
      }
  }
  free(shape);
  return diag_errors() == errors && check_orthonormal(fr, md, modes);
}

void read_modal_file(reader *r, const yaml_node_t *named, const ir_body *b, ir_flex *fx) {
  char *path = model_relative_path(r, named);
  fx->modal_file = path;
  int errors = diag_errors();
  yaml_document_t doc;
  bool unreadable = false;
  if (load_named_yaml(path, &doc, &unreadable)) {
    reader fr; /* the file's own reader: its diagnostics name that file; no parameters */
    memset(&fr, 0, sizeof fr);
    fr.path = path;
    fr.doc = &doc;
    ir_modal_data *md = xcalloc(1, sizeof *md);
    if (read_content(&fr, md)) fx->modal = md;
    else free_modal_data(md);
    yaml_document_delete(&doc);
  } else if (unreadable) {
    if (errno == EFBIG)
      error_at(r, loc_of(named), "the modal data file '%s' is larger than the limit of %.0f bytes "
               "(MBCC_MAX_INPUT=BYTES lifts it)", show_text(r, path, strlen(path)),
               limit_value("MBCC_MAX_INPUT", LIMIT_INPUT_BYTES));
    else
      error_at(r, loc_of(named), "cannot read the modal data file '%s': %s", show_text(r, path, strlen(path)),
               strerror(errno));
    return;
  }
  if (diag_errors() > errors)
    note_at(r, loc_of(named), "in the modal data file of flexible body '%s'", b->name);
}
