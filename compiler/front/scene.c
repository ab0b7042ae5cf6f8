/* scene.c: scenes (docs/model-format.md): each scene's overrides are
 * parsed and checked; the chosen one (ir_read's 'scene') is applied after
 * the whole model is read: settings, outputs, deactivated elements, modal
 * choices and joints on flexible bodies (scene.h). */
#include "scene.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "reader.h"
#include "bounds.h"

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

static void parse_scene(reader *r, yaml_node_t *key, yaml_node_t *value,
                        const sim_settings *base_sim, bool chosen) {
  ir_model *model = r->model;
  const char *name = show_text(r, scalar_text(key), scalar_length(key));
  char what[SHOWN_SIZE];
  snprintf(what, sizeof what, "scene '%s'", name);
  mapping m;
  if (!map_open(&m, r, value, loc_of(key), "%s", what))
    return;
  static const char *const keys[] = {"simulation", "outputs", "deactivate", "gravity", "bodies", NULL};
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
    free_scene_flex(flex, model->nbodies);
    return;
  }
  s->found = true;
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
  model->sim = s->sim;
}

void free_chosen_scene(chosen_scene *s, int nbodies) {
  free_scene_flex(s->flex, nbodies);
  free(s->name);
  free_outputs(s->outputs, s->noutputs);
  free(s->joint_off);
  free(s->driver_off);
  free(s->force_off);
  memset(s, 0, sizeof *s);
}
