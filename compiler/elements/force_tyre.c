/* force_tyre.c: the tyre of a wheel body on a road (kernel
 * runtime/core/elements/mb_tyre.h), and the top-level 'roads' it rolls on.
 * The road's data are copied into the tyre's parameter pool (kind, then the
 * road's numbers), so the kernel needs nothing but its record's reals. */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "element.h"
#include "emit_force.h"
#include "names.h"
#include "reader.h"

/* ---------------------------------------------------------------------------
 * roads
 * ------------------------------------------------------------------------- */

static const char *const road_type_names[] = {"flat", "cosine_bump", "table", NULL};

/* a strictly rising list of at least 2 numbers */
static bool rising(const double *v, int n) {
  if (n < 2) return false;
  for (int i = 1; i < n; i++)
    if (!(v[i] > v[i - 1])) return false;
  return true;
}

/* a list of numbers (a YAML sequence) into a new array */
static double *number_list(reader *r, yaml_node_t *n, const char *label, int *count) {
  *count = 0;
  if (n->type != YAML_SEQUENCE_NODE) {
    error_at(r, loc_of(n), "%s: expected a list of numbers, got %s", label, show_node(r, n));
    return NULL;
  }
  int len = seq_length(n);
  double *v = xcalloc((size_t)len + 1, sizeof *v);
  for (int i = 0; i < len; i++)
    if (!to_number(r, seq_item(r, n, i), label, &v[i])) { free(v); return NULL; }
  *count = len;
  return v;
}

/* The table road's CSV file: a header line "x\y, y_0, y_1, ...", then one
 * line per x: "x_i, z_i0, z_i1, ...".  Lines starting with '#' are comments. */
static bool read_road_csv(reader *r, yaml_node_t *n, ir_road *rd) {
  char *path = model_relative_path(r, n);
  FILE *f = fopen(path, "r");
  if (!f) {
    error_at(r, loc_of(n), "road '%s': cannot open '%s': %s", rd->name, path, strerror(errno));
    free(path);
    return false;
  }
  char line[65536];
  int lineno = 0, cap = 0;
  bool ok = true, header = true;
  double *xs = NULL, *zs = NULL;
  while (ok && fgets(line, sizeof line, f)) {
    lineno++;
    char *p = line;
    while (*p == ' ' || *p == '\t') p++;
    if (*p == '#' || *p == '\n' || *p == '\r' || *p == 0) continue;
    double vals[4096];
    int nv = 0;
    char *cell = p;
    for (;;) { /* split on commas */
      char *comma = strchr(cell, ',');
      if (comma) *comma = 0;
      if (!(header && nv == 0)) {
        char *end;
        errno = 0;
        double v = strtod(cell, &end);
        while (*end == ' ' || *end == '\t' || *end == '\r' || *end == '\n') end++;
        if (end == cell || *end != 0 || !isfinite(v) || nv >= 4096) {
          error_at(r, loc_of(n), "road '%s': %s:%d: cell %d is not a number", rd->name, path, lineno, nv + 1);
          ok = false;
          break;
        }
        vals[nv] = v;
      }
      nv++;
      if (!comma) break;
      cell = comma + 1;
    }
    if (!ok) break;
    if (header) {
      rd->ny = nv - 1;
      rd->y = xcalloc((size_t)rd->ny + 1, sizeof *rd->y);
      memcpy(rd->y, vals + 1, sizeof(double) * (size_t)rd->ny);
      header = false;
      continue;
    }
    if (nv != rd->ny + 1) {
      error_at(r, loc_of(n), "road '%s': %s:%d: %d heights, expected %d (one per y of the header)", rd->name,
               path, lineno, nv - 1, rd->ny);
      ok = false;
      break;
    }
    if (rd->nx == cap) {
      cap = cap ? 2 * cap : 64;
      double *more_x = realloc(xs, sizeof *xs * (size_t)cap);
      if (!more_x) out_of_memory(); /* unwinds to ir_read, which reports it */
      xs = more_x;
      double *more_z = realloc(zs, sizeof *zs * (size_t)cap * (size_t)rd->ny);
      if (!more_z) out_of_memory();
      zs = more_z;
    }
    xs[rd->nx] = vals[0];
    memcpy(zs + (size_t)rd->nx * (size_t)rd->ny, vals + 1, sizeof(double) * (size_t)rd->ny);
    rd->nx++;
  }
  fclose(f);
  if (ok && header) {
    error_at(r, loc_of(n), "road '%s': '%s' has no header line (x\\y, y_0, y_1, ...)", rd->name, path);
    ok = false;
  }
  rd->x = xs;
  rd->z = zs;
  free(path);
  return ok;
}

void parse_road(reader *r, yaml_node_t *key, yaml_node_t *value) {
  ir_model *model = r->model;
  ir_road *rd = &model->roads[model->nroads++];
  rd->loc = loc_of(key);
  rd->name = xstrndup(scalar_text(key), scalar_length(key));
  for (int i = 0; i < model->nroads - 1; i++)
    if (strcmp(model->roads[i].name, rd->name) == 0) {
      error_at(r, rd->loc, "road '%s' is defined twice", rd->name);
      note_at(r, model->roads[i].loc, "road '%s' is defined here", rd->name);
    }
  mapping m;
  if (!map_open(&m, r, value, rd->loc, "road '%s'", rd->name)) return;
  int type;
  if (!get_choice(&m, "type", "road type", road_type_names, true, &type)) {
    map_close(&m);
    return;
  }
  rd->kind = (ir_road_kind)type;
  if (rd->kind == ROAD_FLAT) {
    static const char *const keys[] = {"type", "height", NULL};
    map_check_keys(&m, keys);
    get_number(&m, "height", false, &rd->height);
  } else if (rd->kind == ROAD_COSINE_BUMP) {
    static const char *const keys[] = {"type", "height", "length", "start", "y_range", NULL};
    map_check_keys(&m, keys);
    rd->y_range[0] = -INFINITY;
    rd->y_range[1] = INFINITY;
    get_number(&m, "height", true, &rd->height);
    get_positive(&m, "length", true, &rd->length);
    get_number(&m, "start", true, &rd->start);
    if (get_vector(&m, "y_range", 2, false, rd->y_range) && !(rd->y_range[1] > rd->y_range[0]))
      error_at(r, m.last_loc, "'y_range' of road '%s' must be [y_min, y_max] with y_min < y_max", rd->name);
  } else {
    static const char *const keys[] = {"type", "x", "y", "z", "file", NULL};
    map_check_keys(&m, keys);
    yaml_node_t *file = map_get(&m, "file");
    if (file != NULL) {
      for (int i = 0; keys[i + 1] && i < 3; i++)
        if (map_has(&m, keys[i + 1]))
          map_reject(&m, keys[i + 1], "give either 'file' or 'x', 'y' and 'z'");
      if (file->type != YAML_SCALAR_NODE)
        error_at(r, loc_of(file), "'file': expected a file name, got %s", show_node(r, file));
      else if (!read_road_csv(r, file, rd)) {
        map_close(&m);
        return;
      }
    } else {
      yaml_node_t *xn = map_require(&m, "x", true, "a rising list of x"),
                  *yn = map_require(&m, "y", true, "a rising list of y"),
                  *zn = map_require(&m, "z", true, "a list of rows of heights, one row per x");
      if (!xn || !yn || !zn) { map_close(&m); return; }
      rd->x = number_list(r, xn, "'x'", &rd->nx);
      rd->y = number_list(r, yn, "'y'", &rd->ny);
      if (!rd->x || !rd->y) { map_close(&m); return; }
      if (zn->type != YAML_SEQUENCE_NODE || seq_length(zn) != rd->nx) {
        error_at(r, loc_of(zn), "'z' of road '%s': expected %d rows (one per x) of %d heights (one per y)",
                 rd->name, rd->nx, rd->ny);
        map_close(&m);
        return;
      }
      rd->z = xcalloc((size_t)rd->nx * (size_t)rd->ny + 1, sizeof *rd->z);
      for (int i = 0; i < rd->nx; i++) {
        yaml_node_t *row = seq_item(r, zn, i);
        if (row->type != YAML_SEQUENCE_NODE || seq_length(row) != rd->ny) {
          error_at(r, loc_of(row), "row %d of 'z' of road '%s': expected %d heights (one per y)", i + 1, rd->name,
                   rd->ny);
          continue;
        }
        to_vector(r, row, "'z'", rd->ny, rd->z + (size_t)i * (size_t)rd->ny);
      }
    }
    if (rd->x && !rising(rd->x, rd->nx))
      error_at(r, rd->loc, "road '%s': x must rise strictly, at least 2 values", rd->name);
    if (rd->y && !rising(rd->y, rd->ny))
      error_at(r, rd->loc, "road '%s': y must rise strictly, at least 2 values", rd->name);
  }
  map_close(&m);
}

/* ---------------------------------------------------------------------------
 * the tyre
 * ------------------------------------------------------------------------- */

static const char *const tyre_model_names[] = {"gim_nikravesh", "fiala", NULL};

static void parse_tyre(mapping *m, ir_force *f) {
  reader *r = m->r;
  ir_tyre *ty = &f->tyre;
  ty->road = -1;
  ty->axis[1] = 1;
  ty->mu0 = ty->mu1 = 1;
  ty->low_speed = 0.5;
  ty->damping_blend = 1e-3;
  if (get_ref(m, "body", NAME_BODY, true, &f->body[0], &f->body_loc[0])) {
    const ir_body *b = &r->model->bodies[f->body[0]];
    memcpy(f->point[0], b->position, sizeof f->point[0]);
    if (b->kind == BODY_GROUND || b->kind == BODY_FLEXIBLE)
      error_at(r, f->body_loc[0], "tyre '%s': the wheel must be a rigid body ('%s' is %s)", f->name, b->name,
               b->kind == BODY_GROUND ? "the ground" : "flexible");
  }
  get_vector(m, "point", 3, false, f->point[0]);
  get_axis(m, "axis", false, ty->axis);
  if (fabs(ty->axis[2]) > 0.9)
    error_at(r, m->last_loc, "tyre '%s': the spin axis is nearly vertical (the wheel would lie flat)", f->name);
  yaml_node_t *road = map_require(m, "road", true, "the name of a road of 'roads'");
  if (road != NULL) {
    for (int i = 0; i < r->model->nroads; i++)
      if (road->type == YAML_SCALAR_NODE && scalar_equals(road, r->model->roads[i].name)) ty->road = i;
    if (ty->road < 0)
      error_at(r, loc_of(road), "tyre '%s': no road named %s in 'roads'", f->name, show_node(r, road));
  }
  get_choice(m, "model", "tyre model", tyre_model_names, false, &ty->model);
  get_positive(m, "radius", true, &ty->radius);
  get_nonnegative(m, "width", false, &ty->width);
  get_positive(m, "radial_stiffness", true, &ty->kz);
  get_nonnegative(m, "radial_damping", false, &ty->cz);
  get_nonnegative(m, "longitudinal_stiffness", false, &ty->ks);
  get_nonnegative(m, "cornering_stiffness", false, &ty->ka);
  get_nonnegative(m, "camber_stiffness", false, &ty->kg);
  get_nonnegative(m, "rolling_resistance", false, &ty->crr);
  get_positive(m, "low_speed", false, &ty->low_speed);
  get_positive(m, "damping_blend", false, &ty->damping_blend);
  yaml_node_t *fr = map_get(m, "friction");
  if (fr != NULL) {
    if (fr->type == YAML_SCALAR_NODE) {
      if (to_number(r, fr, "'friction'", &ty->mu0)) ty->mu1 = ty->mu0;
    } else {
      mapping fm;
      if (map_open(&fm, r, fr, loc_of(fr), "'friction' of tyre '%s'", f->name)) {
        static const char *const keys[] = {"static", "sliding", NULL};
        map_check_keys(&fm, keys);
        get_positive(&fm, "static", true, &ty->mu0);
        ty->mu1 = ty->mu0;
        get_positive(&fm, "sliding", false, &ty->mu1);
        map_close(&fm);
      }
    }
    if (!(ty->mu0 > 0) || !(ty->mu1 > 0))
      error_at(r, loc_of(fr), "tyre '%s': friction coefficients must be > 0", f->name);
  }
}

/* how many reals the road takes in the pool */
static int road_size(const ir_road *rd) {
  switch (rd->kind) {
  case ROAD_FLAT: return 2;
  case ROAD_COSINE_BUMP: return 6;
  case ROAD_TABLE: return 3 + rd->nx + rd->ny + rd->nx * rd->ny;
  }
  return 0;
}

static void lower_tyre(lmodel *L, const ir_force *F, int index, mb_forcedef *d) {
  const ir_tyre *ty = &F->tyre;
  const ir_road *rd = &L->ir->roads[ty->road];
  (void)index;
  /* the marker's z axis is the spin axis; x and y any perpendicular pair */
  const double *z = ty->axis;
  double x[3] = {0, 0, 0}, y[3], C[9];
  x[fabs(z[0]) < 0.6 ? 0 : 2] = 1;
  double dz = x[0] * z[0] + x[1] * z[1] + x[2] * z[2];
  for (int j = 0; j < 3; j++) x[j] -= dz * z[j];
  double xl = sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]);
  for (int j = 0; j < 3; j++) x[j] /= xl;
  y[0] = z[1] * x[2] - z[2] * x[1];
  y[1] = z[2] * x[0] - z[0] * x[2];
  y[2] = z[0] * x[1] - z[1] * x[0];
  for (int i = 0; i < 3; i++) { C[3 * i] = x[i]; C[3 * i + 1] = y[i]; C[3 * i + 2] = z[i]; }
  d->m0 = lower_force_marker(L, F, 0, C);
  double *prm = lower_force_prm(L, d, MB_TYRE_NPRM + road_size(rd));
  if (!prm) return; /* out of memory (lower_force_prm) */
  prm[MB_TYRE_R0] = ty->radius;
  prm[MB_TYRE_WIDTH] = ty->width;
  prm[MB_TYRE_KZ] = ty->kz;
  prm[MB_TYRE_CZ] = ty->cz;
  prm[MB_TYRE_KS] = ty->ks;
  prm[MB_TYRE_KA] = ty->ka;
  prm[MB_TYRE_KG] = ty->kg;
  prm[MB_TYRE_MU0] = ty->mu0;
  prm[MB_TYRE_MU1] = ty->mu1;
  prm[MB_TYRE_CRR] = ty->crr;
  prm[MB_TYRE_MODEL] = ty->model;
  prm[MB_TYRE_VLOW] = ty->low_speed;
  prm[MB_TYRE_DBLEND] = ty->damping_blend;
  double *road = prm + MB_TYRE_ROAD;
  switch (rd->kind) {
  case ROAD_FLAT:
    road[0] = MB_ROAD_FLAT;
    road[1] = rd->height;
    break;
  case ROAD_COSINE_BUMP:
    road[0] = MB_ROAD_COSINE_BUMP;
    road[1] = rd->height;
    road[2] = rd->length;
    road[3] = rd->start;
    /* an absent window: the bump across the whole road */
    road[4] = isfinite(rd->y_range[0]) ? rd->y_range[0] : -1e30;
    road[5] = isfinite(rd->y_range[1]) ? rd->y_range[1] : 1e30;
    break;
  case ROAD_TABLE:
    road[0] = MB_ROAD_TABLE;
    road[1] = rd->nx;
    road[2] = rd->ny;
    memcpy(road + 3, rd->x, sizeof(double) * (size_t)rd->nx);
    memcpy(road + 3 + rd->nx, rd->y, sizeof(double) * (size_t)rd->ny);
    memcpy(road + 3 + rd->nx + rd->ny, rd->z, sizeof(double) * (size_t)rd->nx * (size_t)rd->ny);
    break;
  }
}

static int emit_tyre(FILE *f, const lmodel *L, int k) {
  const mb_forcedef *d = &L->force[k];
  int b0 = L->marker[d->m0].body;
  fprintf(f, "    mb_real Fv[3], Tv[3];\n"
             "    mb_tyre(&k%d, force_prm + %d, Fv, Tv, 0, 0);\n",
          d->m0, d->padr);
  char P[32];
  snprintf(P, sizeof P, "k%d.P", d->m0);
  int n = emit_cols(f, L, d->m0, P, "Fv", "Tv", "    ");
  if (n < 0) return -1;
  emit_add_cols(f, L->body[b0].vadr, n);
  return 0;
}

static const char *const tyre_keys[] = {
    "type",   "body",  "point",  "axis",  "road", "model",
    "radius", "width", "radial_stiffness", "radial_damping", "longitudinal_stiffness",
    "cornering_stiffness", "camber_stiffness", "friction", "rolling_resistance", "low_speed",
    "damping_blend", NULL};

const element_desc element_tyre = {
    .family = ELEMENT_FORCE, .type = "tyre", .ir_kind = FORCE_TYRE,
    ELEMENT_RUNTIME_KIND(MB_FORCE_TYRE), .keys = tyre_keys,
    .prm_layout = "R0, width, Kz, Cz, Ks, Ka, Kg, mu0, mu1, Crr, model, low speed, damping blend; road",
    .parse = parse_tyre, .lower = lower_tyre, .emit_eval = emit_tyre};
