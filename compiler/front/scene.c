/* scene.c: scenes (docs/model-format.md): each scene's overrides are
 * parsed and checked; the chosen one (ir_read's 'scene') is applied after
 * the whole model is read: settings, outputs, deactivated elements, modal
 * choices and joints on flexible bodies (scene.h). */
#include "scene.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "reader.h"
#include "bounds.h"
#include "diag.h"

/* ---------------------------------------------------------------------------
 * scenes
 * ------------------------------------------------------------------------- */

static void parse_deactivate(reader *r, yaml_node_t *n, bool *joint_off, bool *driver_off,
                             bool *force_off) {
  if (n->type != YAML_SEQUENCE_NODE) {
    error_at(r, loc_of(n), "'deactivate': expected a list of joint, driver or force names, got %s",
             show_node(r, n));
    return;
  }
  for (int i = 0; i < seq_length(n); i++) {
    yaml_node_t *item = seq_item(r, n, i);
    if (item->type != YAML_SCALAR_NODE) {
      error_at(r, loc_of(item), "'deactivate' must list joint, driver or force names (got %s)",
               show_node(r, item));
      continue;
    }
    const char *text = scalar_text(item);
    size_t length = scalar_length(item);
    name_entry *e = strlen(text) == length ? table_find(&r->names, text) : NULL;
    if (e != NULL && e->kind == NAME_JOINT) {
      joint_off[e->index] = true;
    } else if (e != NULL && e->kind == NAME_DRIVER) {
      driver_off[e->index] = true;
    } else if (e != NULL && e->kind == NAME_FORCE) {
      force_off[e->index] = true;
    } else if (e != NULL) {
      error_at(r, loc_of(item), "'%s' is a%s %s; only joints, drivers and forces can be deactivated",
               e->name, e->kind == NAME_OUTPUT ? "n" : "", name_kind_words[e->kind]);
    } else {
      name_list l = {.length = 0};
      list_names_of_kind(r, NAME_JOINT, &l);
      list_names_of_kind(r, NAME_DRIVER, &l);
      list_names_of_kind(r, NAME_FORCE, &l);
      error_at(r, loc_of(item), "unknown joint, driver or force '%s' in 'deactivate' (%s%s)",
               show_text(r, text, length), l.count ? "expected one of: " : "the model has none",
               l.text);
    }
  }
}

static void free_scene_flex(ir_flex **flex, int nbodies) {
  if (!flex) return;
  for (int b = 0; b < nbodies; b++)
    if (flex[b]) { free(flex[b]->list); free(flex[b]->ratios); free(flex[b]); }
  free(flex);
}

/* A scene's 'bodies': flexible body name -> {modes, damping, coupling}, each
 * overriding the body's own (coupling: rigid makes the body rigid).  Returns
 * per body the settings the scene gives it (NULL for the others). */
static ir_flex **parse_scene_bodies(reader *r, yaml_node_t *n, const char *what) {
  ir_model *model = r->model;
  mapping m;
  if (!map_open(&m, r, n, loc_of(n), "'bodies' of %s", what))
    return NULL;
  ir_flex **flex = xcalloc((size_t)model->nbodies + 1, sizeof *flex);
  for (int i = 0; i < m.npairs; i++) {
    yaml_node_t *key = map_key_node(&m, i), *value = map_value_node(&m, i);
    m.handled[i] = true;
    int b = -1;
    for (int k = 1; k < model->nbodies; k++)
      if (model->bodies[k].name && scalar_equals(key, model->bodies[k].name)) b = k;
    if (b < 0 || !model->bodies[b].flex) {
      name_list l = {.length = 0};
      for (int k = 1; k < model->nbodies; k++)
        if (model->bodies[k].flex) name_list_add(&l, model->bodies[k].name);
      error_at(r, loc_of(key), "%s %s in 'bodies' of %s (%s%s)",
               b < 0 ? "unknown body" : "not a flexible body:", show_node(r, key), what,
               l.count ? "expected a flexible body: " : "the model has no flexible body", l.text);
      continue;
    }
    mapping bm;
    char label[SHOWN_SIZE + 40];
    snprintf(label, sizeof label, "body '%s' in %s", model->bodies[b].name, what);
    if (!map_open(&bm, r, value, loc_of(key), "%s", label))
      continue;
    static const char *const keys[] = {"modes", "damping", "coupling", NULL};
    map_check_keys(&bm, keys);
    /* start from the body's own settings; the lists are copied */
    const ir_flex *own = model->bodies[b].flex;
    ir_flex *fx = xcalloc(1, sizeof *fx);
    fx->select = own->select; fx->count = own->count; fx->max_frequency = own->max_frequency;
    fx->damping = own->damping; fx->ratio = own->ratio; fx->coupling = own->coupling;
    bool new_list = map_has(&bm, "modes"), new_ratios = map_has(&bm, "damping");
    if (!new_list && own->nlist) {
      fx->list = xcalloc((size_t)own->nlist, sizeof *fx->list);
      memcpy(fx->list, own->list, sizeof *fx->list * (size_t)own->nlist);
      fx->nlist = own->nlist;
    }
    if (!new_ratios && own->nratios) {
      fx->ratios = xcalloc((size_t)own->nratios + 1, sizeof *fx->ratios);
      memcpy(fx->ratios, own->ratios, sizeof *fx->ratios * (size_t)own->nratios);
      fx->nratios = own->nratios;
    }
    parse_modal_settings(&bm, fx);
    map_close(&bm);
    if (flex[b]) { free(flex[b]->list); free(flex[b]->ratios); free(flex[b]); }
    flex[b] = fx;
  }
  map_close(&m);
  return flex;
}

/* the index of body 'n' (a name), or -1 after reporting; ground is refused */
static int scene_body(reader *r, yaml_node_t *n, const char *where) {
  ir_model *model = r->model;
  if (n->type == YAML_SCALAR_NODE)
    for (int b = 1; b < model->nbodies; b++)
      if (model->bodies[b].name && scalar_equals(n, model->bodies[b].name)) return b;
  if (scalar_equals(n, "ground")) {
    error_at(r, loc_of(n), "the ground cannot be removed (in %s)", where);
    return -1;
  }
  name_list l = {.length = 0};
  for (int b = 1; b < model->nbodies; b++) name_list_add(&l, model->bodies[b].name);
  error_at(r, loc_of(n), "unknown body %s in %s (%s%s)", show_node(r, n), where,
           l.count ? "expected one of: " : "the model has none", l.text);
  return -1;
}

/* 'remove: [body, ...]' */
static void parse_remove(reader *r, yaml_node_t *n, bool *removed) {
  if (n->type != YAML_SEQUENCE_NODE) {
    error_at(r, loc_of(n), "'remove': expected a list of body names, got %s", show_node(r, n));
    return;
  }
  for (int i = 0; i < seq_length(n); i++) {
    int b = scene_body(r, seq_item(r, n, i), "'remove'");
    if (b > 0) removed[b] = true;
  }
}

/* the column of 'name' in a CSV header (comma-separated), or -1 */
static int csv_column(const char *header, const char *name) {
  size_t length = strlen(name);
  int column = 0;
  for (const char *p = header; p; column++) {
    const char *end = strpbrk(p, ",\r\n");
    size_t field = end ? (size_t)(end - p) : strlen(p);
    if (field == length && memcmp(p, name, length) == 0) return column;
    p = end && *end == ',' ? end + 1 : NULL;
  }
  return -1;
}

/* A results CSV of the full model (mbcc run): for every body with a
 * 'position' (no point, no node, all components) and an 'orientation'
 * output among the base model's outputs, its rows t, x, y, z, e0..e3 in
 * motion[b]; rows whose t does not rise are skipped.  false after reporting. */
static bool read_motion(reader *r, yaml_node_t *n, chosen_scene *s) {
  ir_model *model = r->model;
  const char *base = diag_loc_file(loc_of(n), r->path);
  const char *slash = strrchr(base, '/');
  size_t dl = slash && scalar_text(n)[0] != '/' ? (size_t)(slash - base + 1) : 0;
  char *path = xcalloc(dl + scalar_length(n) + 1, 1);
  memcpy(path, base, dl);
  memcpy(path + dl, scalar_text(n), scalar_length(n));
  s->motion_path = path;
  s->motion_loc = loc_of(n);
  FILE *f = fopen(path, "rb");
  if (f == NULL) {
    error_at(r, loc_of(n), "cannot read the recorded motion '%s': %s", path, strerror(errno));
    return false;
  }
  size_t capacity = 1 << 16, length = 0;
  char *data = xcalloc(capacity + 1, 1);
  for (;;) {
    length += fread(data + length, 1, capacity - length, f);
    if (length < capacity) break;
    if ((double)capacity > 64.0 * LIMIT_INPUT_BYTES) {
      fclose(f);
      free(data);
      error_at(r, loc_of(n), "the recorded motion '%s' is larger than %.0f bytes", path, 64.0 * LIMIT_INPUT_BYTES);
      return false;
    }
    char *bigger = realloc(data, 2 * capacity + 1);
    if (bigger == NULL) out_of_memory();
    data = bigger;
    capacity *= 2;
  }
  fclose(f);
  data[length] = '\0';
  int rows = 0;
  for (size_t i = 0; i < length; i++) rows += data[i] == '\n';
  s->motion = xcalloc((size_t)model->nbodies, sizeof *s->motion);
  /* the columns of each recorded body */
  int column[64][8];
  int bodies[64], nrecorded = 0;
  for (int b = 1; b < model->nbodies && nrecorded < 64; b++) {
    const ir_output *pos = NULL, *ori = NULL;
    for (int k = 0; k < model->noutputs; k++) {
      const ir_output *o = &model->outputs[k];
      if (o->body != b) continue;
      if (o->kind == OUT_POSITION && !o->has_point && o->node < 0 && o->component < 0 && o->scale == 1) pos = o;
      if (o->kind == OUT_ORIENTATION) ori = o;
    }
    if (!pos || !ori) continue;
    char name[SHOWN_SIZE + 8];
    bool all = true;
    static const char *const suffix[8] = {NULL, "x", "y", "z", "e0", "e1", "e2", "e3"};
    column[nrecorded][0] = csv_column(data, "t");
    for (int c = 1; c < 8; c++) {
      snprintf(name, sizeof name, "%s.%s", c < 4 ? pos->name : ori->name, suffix[c]);
      column[nrecorded][c] = csv_column(data, name);
      all = all && column[nrecorded][c] >= 0;
    }
    if (all && column[nrecorded][0] >= 0) bodies[nrecorded++] = b;
  }
  for (int i = 0; i < nrecorded; i++) s->motion[bodies[i]] = xcalloc((size_t)rows * 8 + 8, sizeof(double));
  /* the data rows */
  char *line = strchr(data, '\n');
  int count = 0, lineno = 1;
  bool ok = true;
  double *fields = xcalloc(4096, sizeof *fields);
  while (ok && line != NULL && line[1] != '\0') {
    line++;
    lineno++;
    char *end = strchr(line, '\n');
    if (end) *end = '\0';
    int nfields = 0;
    for (char *p = line; p && nfields < 4096; nfields++) {
      char *stop;
      fields[nfields] = strtod(p, &stop);
      if (stop == p || (*stop != ',' && *stop != '\0' && *stop != '\r')) {
        error_at(r, loc_of(n), "the recorded motion '%s', line %d: field %d is not a number", path, lineno, nfields + 1);
        ok = false;
        break;
      }
      p = *stop == ',' ? stop + 1 : NULL;
    }
    for (int i = 0; ok && i < nrecorded; i++) {
      double *row = s->motion[bodies[i]] + 8 * count;
      for (int c = 0; c < 8; c++) row[c] = column[i][c] < nfields ? fields[column[i][c]] : 0;
    }
    double t = nrecorded ? s->motion[bodies[0]][8 * count] : 0;
    if (ok && (count == 0 || t > s->motion[bodies[0]][8 * (count - 1)])) count++;
    line = end;
  }
  free(fields);
  free(data);
  s->nmotion_rows = count;
  if (ok && nrecorded > 0 && count < 2) {
    error_at(r, loc_of(n), "the recorded motion '%s' has fewer than 2 rows", path);
    ok = false;
  }
  return ok;
}

/* 'rig: {bodies: [kept, ...], attachments: ground | {motion: results.csv}}':
 * every other body removed */
static bool parse_rig(reader *r, yaml_node_t *n, const char *what, bool *removed, chosen_scene *s,
                      bool chosen) {
  mapping m;
  if (!map_open(&m, r, n, loc_of(n), "'rig' of %s", what)) return false;
  static const char *const keys[] = {"bodies", "attachments", NULL};
  map_check_keys(&m, keys);
  yaml_node_t *list = map_require(&m, "bodies", true, "a list of the bodies kept on the rig");
  bool ok = list != NULL;
  if (list != NULL && (list->type != YAML_SEQUENCE_NODE || seq_length(list) == 0)) {
    error_at(r, loc_of(list), "'bodies' of the rig: expected a list of body names, got %s", show_node(r, list));
    ok = false;
  } else if (list != NULL) {
    bool *kept = xcalloc((size_t)r->model->nbodies, sizeof *kept);
    for (int i = 0; i < seq_length(list); i++) {
      int b = scene_body(r, seq_item(r, list, i), "'bodies' of the rig");
      if (b > 0) kept[b] = true;
    }
    for (int b = 1; b < r->model->nbodies; b++) removed[b] = removed[b] || !kept[b];
    free(kept);
  }
  yaml_node_t *at = map_get(&m, "attachments");
  if (at != NULL && at->type == YAML_MAPPING_NODE) {
    mapping am;
    map_open(&am, r, at, loc_of(at), "'attachments' of the rig");
    static const char *const akeys[] = {"motion", NULL};
    map_check_keys(&am, akeys);
    yaml_node_t *file = map_require(&am, "motion", true, "a results CSV of the full model");
    if (file != NULL && (file->type != YAML_SCALAR_NODE || scalar_length(file) == 0)) {
      error_at(r, loc_of(file), "'motion': expected the name of a results CSV, got %s", show_node(r, file));
      ok = false;
    } else if (file != NULL && chosen) {
      ok = read_motion(r, file, s) && ok;
    }
    map_close(&am);
  } else if (at != NULL && !scalar_equals(at, "ground")) {
    error_at(r, loc_of(at), "'attachments' of the rig: expected 'ground' or {motion: results.csv}, got %s",
             show_node(r, at));
    ok = false;
  }
  map_close(&m);
  return ok;
}

/* 'replace: {joint: {type: bushing, stiffness: [6], damping: [6]}}' */
static scene_replacement *parse_replace(reader *r, yaml_node_t *n, const char *what, int *count) {
  ir_model *model = r->model;
  mapping m;
  *count = 0;
  if (!map_open(&m, r, n, loc_of(n), "'replace' of %s", what)) return NULL;
  scene_replacement *out = xcalloc((size_t)m.npairs + 1, sizeof *out);
  for (int i = 0; i < m.npairs; i++) {
    if (m.handled[i]) continue;
    m.handled[i] = true;
    yaml_node_t *key = map_key_node(&m, i), *value = map_value_node(&m, i);
    int j = -1;
    for (int k = 0; k < model->njoints; k++)
      if (model->joints[k].name && scalar_equals(key, model->joints[k].name)) j = k;
    if (j < 0) {
      name_list l = {.length = 0};
      list_names_of_kind(r, NAME_JOINT, &l);
      error_at(r, loc_of(key), "unknown joint %s in 'replace' (%s%s)", show_node(r, key),
               l.count ? "expected one of: " : "the model has none", l.text);
      continue;
    }
    if (model->joints[j].kind == JOINT_DISTANCE) {
      error_at(r, loc_of(key), "joint '%s' is a distance joint: it has two points, a bushing one; "
               "replace it by a spring_damper in 'forces' and deactivate it instead", model->joints[j].name);
      continue;
    }
    mapping bm;
    if (!map_open(&bm, r, value, loc_of(key), "the replacement of joint '%s'", model->joints[j].name)) continue;
    static const char *const keys[] = {"type", "stiffness", "damping", NULL};
    map_check_keys(&bm, keys);
    static const char *const types[] = {"bushing", NULL};
    int type = 0;
    scene_replacement *rp = &out[*count];
    bool ok = get_choice(&bm, "type", "replacement", types, true, &type);
    ok = get_vector(&bm, "stiffness", 6, true, rp->k6) && ok;
    if (map_has(&bm, "damping")) ok = get_vector(&bm, "damping", 6, false, rp->c6) && ok;
    for (int k = 0; ok && k < 6; k++)
      if (rp->k6[k] < 0 || rp->c6[k] < 0) {
        error_at(r, loc_of(key), "the bushing replacing joint '%s' needs stiffness and damping >= 0",
                 model->joints[j].name);
        ok = false;
      }
    map_close(&bm);
    if (!ok) continue;
    rp->joint = j;
    rp->loc = loc_of(key);
    (*count)++;
  }
  map_close(&m);
  return out;
}

static void parse_scene(reader *r, yaml_node_t *key, yaml_node_t *value,
                        const sim_settings *base_sim, bool chosen) {
  ir_model *model = r->model;
  const char *name = show_text(r, scalar_text(key), scalar_length(key));
  char what[SHOWN_SIZE];
  snprintf(what, sizeof what, "scene '%s'", name);
  mapping m;
  if (!map_open(&m, r, value, loc_of(key), "%s", what))
    return;
  static const char *const keys[] = {"simulation", "outputs", "deactivate", "gravity", "bodies",
                                     "remove", "replace", "rig", NULL};
  map_check_keys(&m, keys);

  sim_settings sim = *base_sim;
  yaml_node_t *n = map_get(&m, "simulation");
  if (n != NULL) {
    char label[SHOWN_SIZE + 20];
    snprintf(label, sizeof label, "'simulation' of %s", what);
    parse_sim(r, n, label, FROM_SCENE, &sim);
  }
  ir_sim merged;
  sim_finish(r, &sim, true, &merged);

  ir_output *outputs = NULL;
  int noutputs = 0;
  n = map_get(&m, "outputs");
  if (n != NULL) {
    name_table scene_names = {NULL, 0, 0};
    parse_outputs(r, n, &scene_names, &outputs, &noutputs);
    table_free(&scene_names);
  }
  bool *joint_off = xcalloc((size_t)model->njoints, sizeof *joint_off);
  bool *driver_off = xcalloc((size_t)model->ndrivers, sizeof *driver_off);
  bool *force_off = xcalloc((size_t)model->nforces, sizeof *force_off);
  n = map_get(&m, "deactivate");
  if (n != NULL)
    parse_deactivate(r, n, joint_off, driver_off, force_off);
  ir_flex **flex = NULL;
  n = map_get(&m, "bodies");
  if (n != NULL)
    flex = parse_scene_bodies(r, n, what);
  bool *body_removed = xcalloc((size_t)model->nbodies, sizeof *body_removed);
  n = map_get(&m, "remove");
  if (n != NULL)
    parse_remove(r, n, body_removed);
  n = map_get(&m, "rig");
  chosen_scene *cs = &r->scene;
  bool rig = n != NULL && parse_rig(r, n, what, body_removed, cs, chosen);
  scene_replacement *replace = NULL;
  int nreplace = 0;
  n = map_get(&m, "replace");
  if (n != NULL)
    replace = parse_replace(r, n, what, &nreplace);
  double gravity[3];
  bool has_gravity = get_vector(&m, "gravity", 3, false, gravity);
  bool has_outputs = map_has(&m, "outputs");
  map_close(&m);

  chosen_scene *s = &r->scene;
  if (!chosen) {
    free_outputs(outputs, noutputs);
    free(joint_off);
    free(driver_off);
    free(force_off);
    free(body_removed);
    free(replace);
    free_scene_flex(flex, model->nbodies);
    return;
  }
  s->body_removed = body_removed;
  s->rig = rig;
  s->replace = replace;
  s->nreplace = nreplace;
  s->found = true;
  s->nbodies = model->nbodies;
  s->name = xstrndup(scalar_text(key), scalar_length(key));
  s->has_gravity = has_gravity;
  memcpy(s->gravity, gravity, sizeof gravity);
  s->has_outputs = has_outputs;
  s->outputs = outputs;
  s->noutputs = noutputs;
  s->joint_off = joint_off;
  s->driver_off = driver_off;
  s->force_off = force_off;
  s->sim = merged;
  s->jof_list = sim.jof_list;
  s->flex = flex;
}

/* Every scene is validated; the one named 'chosen' is kept in r->scene. */
void parse_scenes(reader *r, yaml_node_t *n, const sim_settings *base_sim,
                  const char *chosen) {
  mapping m;
  if (!map_open(&m, r, n, loc_of(n), "'scenes'"))
    return;
  for (int i = 0; i < m.npairs; i++) {
    if (m.handled[i])
      continue;
    yaml_node_t *key = map_key_node(&m, i);
    bool is_chosen = chosen != NULL && strlen(chosen) == scalar_length(key) &&
                     memcmp(chosen, scalar_text(key), scalar_length(key)) == 0;
    parse_scene(r, key, map_value_node(&m, i), base_sim, is_chosen);
    if (is_chosen && r->model->name != NULL) {
      /* the scene's code is named <model>_<scene> */
      char combined[SHOWN_SIZE];
      snprintf(combined, sizeof combined, "%s_%.*s", r->model->name, (int)scalar_length(key), scalar_text(key));
      const char *why = reserved_c_name(combined);
      if (why != NULL)
        error_at(r, loc_of(key), "scene '%s' would name the code '%s': %s",
                 show_text(r, scalar_text(key), scalar_length(key)), combined, why);
    }
  }
  map_close(&m);
}

void report_unknown_scene(reader *r, yaml_node_t *scenes, const char *chosen) {
  name_list l = {.length = 0};
  if (scenes != NULL && scenes->type == YAML_MAPPING_NODE) {
    yaml_node_pair_t *pair = scenes->data.mapping.pairs.start;
    for (; pair < scenes->data.mapping.pairs.top; pair++) {
      yaml_node_t *key = node_at(r, pair->key);
      if (key->type == YAML_SCALAR_NODE)
        name_list_add(&l, show_text(r, scalar_text(key), scalar_length(key)));
    }
  }
  const char *shown = show_text(r, chosen, strlen(chosen));
  if (l.count == 0)
    error_at(r, scenes ? loc_of(scenes) : file_start,
             "unknown scene '%s' (the model defines no scenes)", shown);
  else
    error_at(r, loc_of(scenes), "unknown scene '%s' (expected one of: %s)", shown, l.text);
}

/* joints on flexible nodes lowered through virtual bodies: all of them
 * (joints_on_flexible: virtual) or those listed */
void mark_virtual_joints(reader *r, yaml_node_t *list) {
  ir_model *model = r->model;
  if (model->sim.joints_on_flexible == JOF_VIRTUAL)
    for (int j = 0; j < model->njoints; j++)
      model->joints[j].via_virtual = model->joints[j].node[0] >= 0 || model->joints[j].node[1] >= 0;
  if (model->sim.joints_on_flexible != JOF_LIST || list == NULL)
    return;
  for (int i = 0; i < seq_length(list); i++) {
    yaml_node_t *item = seq_item(r, list, i);
    int j = -1;
    if (item->type == YAML_SCALAR_NODE)
      for (int k = 0; k < model->njoints; k++)
        if (model->joints[k].name && scalar_equals(item, model->joints[k].name)) j = k;
    if (j < 0) {
      error_at(r, loc_of(item), "'joints_on_flexible': expected 'direct', 'virtual' or a list of joint names (%s is not a joint)", show_node(r, item));
      continue;
    }
    if (model->joints[j].node[0] < 0 && model->joints[j].node[1] < 0) {
      error_at(r, loc_of(item), "'joints_on_flexible': joint '%s' is not on an FE node", model->joints[j].name);
      continue;
    }
    model->joints[j].via_virtual = true;
  }
}

/* ---------------------------------------------------------------------------
 * pruning: removed bodies and what hangs on them, joints made bushings
 * ------------------------------------------------------------------------- */

/* one line of model->pruned, for 'mbcc check --scene' */
static void pruned_add(ir_model *model, const char *fmt, const char *name, const char *why) {
  char line[SHOWN_SIZE * 2];
  snprintf(line, sizeof line, fmt, name, why);
  size_t old = model->pruned ? strlen(model->pruned) : 0, add = strlen(line);
  char *text = xcalloc(old + add + 2, 1);
  if (old) memcpy(text, model->pruned, old);
  memcpy(text + old, line, add);
  text[old + add] = '\n';
  free(model->pruned);
  model->pruned = text;
}

/* bodies connected to the ground through active joints and two-body forces
 * that touch no removed body */
static void reach_ground(const ir_model *model, const bool *removed, bool *reached) {
  memset(reached, 0, sizeof *reached * (size_t)model->nbodies);
  reached[0] = true;
  for (bool changed = true; changed;) {
    changed = false;
    for (int k = 0; k < model->njoints + model->nforces; k++) {
      const int *body = k < model->njoints ? model->joints[k].body : model->forces[k - model->njoints].body;
      bool active = k < model->njoints ? model->joints[k].active : model->forces[k - model->njoints].active;
      int a = body[0], b = body[1];
      if (!active || a < 0 || b < 0 || removed[a] || removed[b] || reached[a] == reached[b]) continue;
      reached[a] = reached[b] = true;
      changed = true;
    }
  }
}

/* remembers a pruned element for scene_mark_pruned_uses */
static void gone_add(chosen_scene *s, const char *section, const char *name) {
  size_t old = s->gone ? strlen(s->gone) : 0, add = strlen(section) + strlen(name) + 2;
  char *text = xcalloc(old + add + 1, 1);
  if (old) memcpy(text, s->gone, old);
  snprintf(text + old, add + 1, "%s %s\n", section, name);
  free(s->gone);
  s->gone = text;
}

static void drop_output(ir_model *model, const ir_output *o, const char *why) {
  diag_note(model->path, o->loc, "output '%s' dropped: %s (scene '%s')", o->name, why, model->scene);
  pruned_add(model, "output '%s' (%s)", o->name, why);
}

/* grows an array of 'count' elements of 'size' bytes by 'more' (zeroed) */
static void *grow(void *array, int count, int more, size_t size) {
  char *bigger = xcalloc((size_t)(count + more) + 1, size);
  if (count) memcpy(bigger, array, (size_t)count * size);
  free(array);
  return bigger;
}

/* ZYX angles (a about z, then b about the new y, then c about the newest x)
 * of the rotation A(t) A(0)^T between two Euler-parameter sets */
static void rotation_since(const double *e_now, const double *e0, double angles[3]) {
  double A[2][9];
  const double *e[2] = {e_now, e0};
  for (int k = 0; k < 2; k++) {
    double w = e[k][0], x = e[k][1], y = e[k][2], z = e[k][3];
    double n = w * w + x * x + y * y + z * z;
    w /= sqrt(n); x /= sqrt(n); y /= sqrt(n); z /= sqrt(n);
    double M[9] = {1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y),
                   2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x),
                   2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)};
    memcpy(A[k], M, sizeof M);
  }
  double R[9];
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < 3; j++)
      R[3 * i + j] = A[0][3 * i] * A[1][3 * j] + A[0][3 * i + 1] * A[1][3 * j + 1] + A[0][3 * i + 2] * A[1][3 * j + 2];
  double sb = -R[6];
  angles[0] = atan2(R[3], R[0]);
  angles[1] = asin(sb > 1 ? 1 : sb < -1 ? -1 : sb);
  angles[2] = atan2(R[7], R[8]);
}

/* The stand-in of removed body 'removed' on a rig driven by its recorded
 * motion: a chain ground -> x -> y -> z (prismatic) -> about z -> about y
 * -> about x (revolute) of six massless (virtual) bodies at the body's
 * initial pose, each joint driven by a table profile (natural cubic spline
 * through the recorded rows) of the body's displacement and of the ZYX
 * angles of its rotation since t = 0.  Returns the last body: the stand-in. */
static int add_driven_chain(ir_model *model, int removed, const double *rows, int nrows, ir_loc loc) {
  const ir_body *B = &model->bodies[removed];
  char *name = xstrdup(B->name);
  double position[3], orientation[4];
  memcpy(position, B->position, sizeof position);
  memcpy(orientation, B->orientation, sizeof orientation);
  int nb = model->nbodies, nj = model->njoints, nd = model->ndrivers;
  model->bodies = grow(model->bodies, nb, 6, sizeof *model->bodies);
  model->joints = grow(model->joints, nj, 6, sizeof *model->joints);
  model->drivers = grow(model->drivers, nd, 6, sizeof *model->drivers);
  static const char *const dof_name[6] = {"x", "y", "z", "rz", "ry", "rx"};
  static const int axis_of[6] = {0, 1, 2, 2, 1, 0};
  double *profile[6];
  for (int k = 0; k < 6; k++) profile[k] = xcalloc(2 * (size_t)nrows, sizeof(double));
  double previous[3] = {0, 0, 0};
  for (int i = 0; i < nrows; i++) {
    const double *row = rows + 8 * i;
    double angles[3];
    rotation_since(row + 4, rows + 4, angles);
    for (int k = 0; k < 3; k++) { /* unwrapped: continuous through +-pi */
      double turn = 2 * acos(-1.0);
      while (i > 0 && angles[k] - previous[k] > turn / 2) angles[k] -= turn;
      while (i > 0 && angles[k] - previous[k] < -turn / 2) angles[k] += turn;
      previous[k] = angles[k];
    }
    for (int k = 0; k < 6; k++) {
      profile[k][2 * i] = row[0];
      profile[k][2 * i + 1] = k < 3 ? row[1 + k] - rows[1 + k] : angles[k - 3];
    }
  }
  for (int k = 0; k < 6; k++) {
    ir_body *v = &model->bodies[nb + k];
    char label[SHOWN_SIZE * 2];
    snprintf(label, sizeof label, "%s_rig_%s", name, dof_name[k]);
    v->name = xstrdup(label);
    v->loc = loc;
    v->kind = BODY_VIRTUAL;
    memcpy(v->position, position, sizeof position);
    memcpy(v->orientation, orientation, sizeof orientation);
    ir_joint *J = &model->joints[nj + k];
    J->name = xstrdup(label);
    J->loc = J->body_loc[0] = J->body_loc[1] = loc;
    J->kind = k < 3 ? JOINT_PRISMATIC : JOINT_REVOLUTE;
    J->body[0] = k == 0 ? 0 : nb + k - 1;
    J->body[1] = nb + k;
    J->node[0] = J->node[1] = -1;
    for (int side = 0; side < 2; side++) {
      memcpy(J->point[side], position, sizeof position);
      J->axis[side][axis_of[k]] = 1;
    }
    J->ref[(axis_of[k] + 1) % 3] = 1;
    J->active = true;
    ir_driver *D = &model->drivers[nd + k];
    snprintf(label, sizeof label, "%s_rig_%s_motion", name, dof_name[k]);
    D->name = xstrdup(label);
    D->loc = loc;
    D->joint = nj + k;
    D->dof = k < 3 ? DRIVER_TRANSLATION : DRIVER_ROTATION;
    D->motion.kind = PROFILE_TABLE;
    D->motion.table = profile[k];
    D->motion.ntable = nrows;
    D->motion.loc = loc;
    D->active = true;
  }
  model->nbodies = nb + 6;
  model->njoints = nj + 6;
  model->ndrivers = nd + 6;
  free(name);
  return nb + 5;
}

static void prune_model(ir_model *model, chosen_scene *s) {
  int nb0 = model->nbodies, nj0 = model->njoints, nf = model->nforces;
  /* the driven chains of a recorded motion add bodies: 'removed' grows */
  bool *removed = xcalloc((size_t)nb0 + 6 * (size_t)(nj0 + nf) + 1, sizeof *removed);
  memcpy(removed, s->body_removed, sizeof *removed * (size_t)nb0);
  int *standin = xcalloc((size_t)nb0 + 1, sizeof *standin);
  /* a rig: the kept side of a joint or a two-body force to a removed body
     is held by the ground at the same place, or by the removed body's
     stand-in that follows its recorded motion */
  for (int k = 0; s->rig && k < nj0 + nf; k++) {
    bool joint = k < nj0;
    const int *body = joint ? model->joints[k].body : model->forces[k - nj0].body;
    if (body[1] < 0 || removed[body[0]] == removed[body[1]]) continue;
    int side = removed[body[0]] ? 0 : 1, gone = body[side];
    if (body[1 - side] == 0) continue; /* between a removed body and the ground: goes */
    int to = 0;
    if (s->motion) {
      if (!s->motion[gone]) {
        diag_error(model->path, s->motion_loc, "the rig's recorded motion '%s' lacks body '%s': the full model must "
                   "output its position (type: position, no point) and its orientation (type: orientation)",
                   s->motion_path, model->bodies[gone].name);
        continue;
      }
      if (!standin[gone])
        standin[gone] = add_driven_chain(model, gone, s->motion[gone], s->nmotion_rows, s->motion_loc);
      to = standin[gone];
    }
    int *changed = joint ? model->joints[k].body : model->forces[k - nj0].body;
    int *node = joint ? model->joints[k].node : model->forces[k - nj0].node;
    changed[side] = to;
    node[side] = -1;
    pruned_add(model, joint ? "joint '%s' attached to %s (rig)" : "force '%s' attached to %s (rig)",
               joint ? model->joints[k].name : model->forces[k - nj0].name,
               to ? "a body driven by the recorded motion" : "the ground");
  }
  free(standin);
  int nb = model->nbodies, nj = model->njoints, nd = model->ndrivers;
  /* bodies that hung on the ground only through removed ones go too */
  bool *before = xcalloc((size_t)nb, sizeof *before), *after = xcalloc((size_t)nb, sizeof *after);
  bool *none = xcalloc((size_t)nb, sizeof *none);
  reach_ground(model, none, before);
  reach_ground(model, removed, after);
  for (int b = 1; b < nb; b++)
    if (removed[b]) {
      pruned_add(model, "body '%s'%s", model->bodies[b].name, "");
      gone_add(s, "bodies", model->bodies[b].name);
    } else if (before[b] && !after[b]) {
      removed[b] = true;
      diag_note(model->path, model->bodies[b].loc, "body '%s' removed too: it hung on the ground only "
                "through removed bodies (scene '%s')", model->bodies[b].name, model->scene);
      pruned_add(model, "body '%s' (%s)", model->bodies[b].name, "connected only through removed bodies");
      gone_add(s, "bodies", model->bodies[b].name);
    }
  free(before);
  free(after);
  free(none);

  bool *joint_gone = xcalloc((size_t)nj + 1, sizeof *joint_gone);
  bool *driver_gone = xcalloc((size_t)nd + 1, sizeof *driver_gone);
  bool *force_gone = xcalloc((size_t)nf + 1, sizeof *force_gone);
  for (int j = 0; j < nj; j++) {
    joint_gone[j] = removed[model->joints[j].body[0]] || removed[model->joints[j].body[1]];
    if (joint_gone[j]) {
      pruned_add(model, "joint '%s'%s", model->joints[j].name, "");
      gone_add(s, "joints", model->joints[j].name);
    }
  }
  /* joints made bushings: a force at the joint's point, in its axes */
  ir_force *bushings = xcalloc((size_t)s->nreplace + 1, sizeof *bushings);
  int nbushings = 0;
  for (int i = 0; i < s->nreplace; i++) {
    const ir_joint *J = &model->joints[s->replace[i].joint];
    if (joint_gone[s->replace[i].joint]) continue;
    joint_gone[s->replace[i].joint] = true;
    ir_force *F = &bushings[nbushings++];
    F->name = xstrdup(J->name);
    F->loc = s->replace[i].loc;
    F->kind = FORCE_BUSHING;
    for (int side = 0; side < 2; side++) {
      F->body[side] = J->body[side];
      F->body_loc[side] = J->body_loc[side];
      F->node[side] = J->node[side];
      memcpy(F->point[side], J->point[side], sizeof F->point[side]);
    }
    /* rows x, y, z: the joint's marker frame (z the axis, x its reference) */
    const double *z = J->axis[0], *x = J->ref;
    double y[3] = {z[1] * x[2] - z[2] * x[1], z[2] * x[0] - z[0] * x[2], z[0] * x[1] - z[1] * x[0]};
    memcpy(F->axes, x, 3 * sizeof *x);
    memcpy(F->axes + 3, y, sizeof y);
    memcpy(F->axes + 6, z, 3 * sizeof *z);
    memcpy(F->k6, s->replace[i].k6, sizeof F->k6);
    memcpy(F->c6, s->replace[i].c6, sizeof F->c6);
    F->active = J->active;
    pruned_add(model, "joint '%s' (%s)", J->name, "replaced by a bushing");
  }
  for (int d = 0; d < nd; d++) {
    driver_gone[d] = joint_gone[model->drivers[d].joint];
    if (driver_gone[d]) {
      pruned_add(model, "driver '%s' (%s)", model->drivers[d].name, "its joint is gone");
      gone_add(s, "drivers", model->drivers[d].name);
    }
  }
  for (int f = 0; f < nf; f++) {
    const ir_force *F = &model->forces[f];
    force_gone[f] = removed[F->body[0]] || (F->body[1] >= 0 && removed[F->body[1]]);
    for (int k = 2; k < F->nsuper; k++) force_gone[f] = force_gone[f] || removed[F->super_body[k]];
    if (force_gone[f]) {
      pruned_add(model, "force '%s'%s", F->name, "");
      gone_add(s, "forces", F->name);
    }
  }

  /* compact, renumbering bodies, joints and drivers */
  int *body_to = xcalloc((size_t)nb, sizeof *body_to), *joint_to = xcalloc((size_t)nj + 1, sizeof *joint_to);
  int *driver_to = xcalloc((size_t)nd + 1, sizeof *driver_to);
  int count = 0;
  for (int b = 0; b < nb; b++) {
    body_to[b] = removed[b] ? -1 : count;
    if (removed[b]) {
      free(model->bodies[b].name);
      ir_flex *fx = model->bodies[b].flex;
      model->bodies[b].flex = NULL;
      free_flex(fx);
    } else {
      model->bodies[count++] = model->bodies[b];
    }
  }
  model->nbodies = count;
  count = 0;
  for (int j = 0; j < nj; j++) {
    joint_to[j] = joint_gone[j] ? -1 : count;
    if (joint_gone[j]) { free(model->joints[j].name); continue; }
    ir_joint *J = &model->joints[count++];
    *J = model->joints[j];
    for (int side = 0; side < 2; side++) J->body[side] = body_to[J->body[side]];
  }
  model->njoints = count;
  count = 0;
  for (int d = 0; d < nd; d++) {
    driver_to[d] = driver_gone[d] ? -1 : count;
    if (driver_gone[d]) { free(model->drivers[d].name); free(model->drivers[d].motion.table); continue; }
    ir_driver *D = &model->drivers[count++];
    *D = model->drivers[d];
    D->joint = joint_to[D->joint];
  }
  model->ndrivers = count;
  ir_force *forces = xcalloc((size_t)nf + (size_t)nbushings + 1, sizeof *forces);
  int *force_to = xcalloc((size_t)nf + 1, sizeof *force_to);
  count = 0;
  for (int f = 0; f < nf + nbushings; f++) {
    ir_force *F = f < nf ? &model->forces[f] : &bushings[f - nf];
    if (f < nf) force_to[f] = force_gone[f] ? -1 : count;
    if (f < nf && force_gone[f]) {
      free(F->name); free(F->scale.table); free(F->stiffness.table); free(F->damping.table);
      free(F->super_body); free(F->super_point); free(F->super_K); free(F->super_C);
      continue;
    }
    forces[count] = *F;
    for (int side = 0; side < 2; side++)
      if (forces[count].body[side] >= 0) forces[count].body[side] = body_to[forces[count].body[side]];
    for (int k = 0; k < forces[count].nsuper; k++) forces[count].super_body[k] = body_to[forces[count].super_body[k]];
    count++;
  }
  free(model->forces);
  free(bushings);
  model->forces = forces;
  model->nforces = count;
  count = 0;
  for (int k = 0; k < model->noutputs; k++) {
    ir_output *o = &model->outputs[k];
    const char *why = NULL;
    if (o->body >= 0 && body_to[o->body] < 0) {
      why = "it refers to a removed body";
    } else if (o->joint >= 0 && joint_to[o->joint] < 0) {
      why = "it refers to a removed or replaced joint";
    } else if (o->driver >= 0 && driver_to[o->driver] < 0) {
      why = "it refers to a removed driver";
    } else if ((o->kind == OUT_FORCE || o->kind == OUT_TYRE) && force_to[o->force] < 0) {
      why = "it refers to a removed force";
    } else if (o->kind == OUT_RELATIVE && (body_to[o->rel_body] < 0 || body_to[o->frame_body] < 0)) {
      why = "it is measured from, or in the axes of, a removed body";
    } else if (o->kind == OUT_CENTER_OF_MASS) {
      for (int i = 0; i < o->ncm_bodies; i++)
        if (body_to[o->cm_bodies[i]] < 0) why = "its 'bodies' include a removed body";
    }
    if (why) { drop_output(model, o, why); free(o->name); free(o->cm_bodies); continue; }
    ir_output *to = &model->outputs[count++];
    *to = *o;
    if (to->body >= 0) to->body = body_to[to->body];
    if (to->joint >= 0) to->joint = joint_to[to->joint];
    if (to->driver >= 0) to->driver = driver_to[to->driver];
    if (to->kind == OUT_FORCE || to->kind == OUT_TYRE) to->force = force_to[to->force];
    if (to->kind == OUT_RELATIVE) {
      to->rel_body = body_to[to->rel_body];
      to->frame_body = body_to[to->frame_body];
    }
    if (to->kind == OUT_CENTER_OF_MASS)
      for (int i = 0; i < to->ncm_bodies; i++) to->cm_bodies[i] = body_to[to->cm_bodies[i]];
  }
  model->noutputs = count;
  free(body_to); free(joint_to); free(driver_to);
  free(joint_gone); free(driver_gone); free(force_gone); free(force_to);
  free(removed);
}

/* A scene that changes a flexible body's modes (or makes it rigid) drops
 * the outputs of modes the body no longer has, with a note. */
void scene_drop_modal_outputs(ir_model *model, const int *modes_of_body) {
  if (model->scene == NULL) return;
  int count = 0;
  for (int k = 0; k < model->noutputs; k++) {
    ir_output *o = &model->outputs[k];
    if (o->kind == OUT_MODAL && o->body >= 0 && model->bodies[o->body].kind == BODY_FLEXIBLE &&
        o->mode >= modes_of_body[o->body]) {
      drop_output(model, o, modes_of_body[o->body] ? "the body has fewer modes in this scene"
                                                   : "the body is rigid in this scene");
      free(o->name);
      continue;
    }
    model->outputs[count++] = *o;
  }
  model->noutputs = count;
}

void apply_scene(ir_model *model, chosen_scene *s) {
  model->scene = s->name;
  s->name = NULL;
  if (s->has_gravity)
    memcpy(model->gravity, s->gravity, sizeof s->gravity);
  if (s->has_outputs) {
    free_outputs(model->outputs, model->noutputs);
    model->outputs = s->outputs;
    model->noutputs = s->noutputs;
    s->outputs = NULL;
    s->noutputs = 0;
  }
  for (int i = 0; i < model->njoints; i++)
    if (s->joint_off[i])
      model->joints[i].active = false;
  for (int i = 0; i < model->ndrivers; i++) {
    int joint = model->drivers[i].joint;
    if (s->driver_off[i] || (joint >= 0 && !model->joints[joint].active))
      model->drivers[i].active = false;
  }
  for (int i = 0; i < model->nforces; i++)
    if (s->force_off[i])
      model->forces[i].active = false;
  for (int b = 0; s->flex && b < model->nbodies; b++) {
    ir_flex *to = model->bodies[b].flex, *from = s->flex[b];
    if (!from || !to) continue;
    free(to->list); free(to->ratios);
    to->select = from->select; to->count = from->count; to->max_frequency = from->max_frequency;
    to->list = from->list; to->nlist = from->nlist;
    to->damping = from->damping; to->ratio = from->ratio;
    to->ratios = from->ratios; to->nratios = from->nratios;
    to->coupling = from->coupling;
    free(from);
    s->flex[b] = NULL;
  }
  if (s->motion_path) { /* the input hash covers the recorded motion */
    model->included = grow(model->included, model->nincluded, 1, sizeof *model->included);
    model->included[model->nincluded++] = xstrdup(s->motion_path);
  }
  bool prunes = s->nreplace > 0 || s->rig;
  for (int b = 1; b < model->nbodies; b++) prunes = prunes || s->body_removed[b];
  if (prunes)
    prune_model(model, s);
  model->sim = s->sim;
}

/* The fields written with parameters inside pruned elements (their YAML
 * text) are marked, so that run-time parameter binding does not look for
 * them in the generated code. */
void scene_mark_pruned_uses(reader *r, yaml_node_t *root) {
  ir_model *model = r->model;
  const char *gone = r->scene.gone;
  if (gone == NULL || model->nuses == 0 || root == NULL || root->type != YAML_MAPPING_NODE) return;
  for (yaml_node_pair_t *p = root->data.mapping.pairs.start; p < root->data.mapping.pairs.top; p++) {
    yaml_node_t *section = node_at(r, p->key), *map = node_at(r, p->value);
    if (section->type != YAML_SCALAR_NODE || map->type != YAML_MAPPING_NODE) continue;
    for (yaml_node_pair_t *q = map->data.mapping.pairs.start; q < map->data.mapping.pairs.top; q++) {
      yaml_node_t *key = node_at(r, q->key), *value = node_at(r, q->value);
      if (key->type != YAML_SCALAR_NODE) continue;
      char line[2 * SHOWN_SIZE];
      snprintf(line, sizeof line, "%.*s %.*s\n", (int)scalar_length(section), scalar_text(section),
               (int)scalar_length(key), scalar_text(key));
      bool found = false;
      for (const char *at = gone; (at = strstr(at, line)) != NULL && !found; at++)
        found = at == gone || at[-1] == '\n';
      if (!found) continue;
      long from = ((long)value->start_mark.line + 1) * 100000 + (long)value->start_mark.column + 1;
      long to = ((long)value->end_mark.line + 1) * 100000 + (long)value->end_mark.column + 1;
      for (int i = 0; i < model->nuses; i++) {
        long at = (long)model->uses[i].loc.line * 100000 + model->uses[i].loc.col;
        if (at >= from && at <= to) model->uses[i].pruned = true;
      }
    }
  }
}

void free_chosen_scene(chosen_scene *s, int nbodies) {
  if (s->found) nbodies = s->nbodies;
  free_scene_flex(s->flex, nbodies);
  free(s->name);
  free_outputs(s->outputs, s->noutputs);
  free(s->joint_off);
  free(s->driver_off);
  free(s->force_off);
  free(s->body_removed);
  free(s->replace);
  for (int b = 0; s->motion && b < nbodies; b++) free(s->motion[b]);
  free(s->motion);
  free(s->motion_path);
  free(s->gone);
  memset(s, 0, sizeof *s);
}
