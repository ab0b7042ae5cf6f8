/* output_flex.c: the outputs of a flexible body: a node's deflection, a
 * modal coordinate, a beam's section forces or stress (kernel:
 * mb_model_outputs, runtime/core/model_generic.c). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bounds.h"
#include "diag.h"
#include "element.h"
#include "fe.h"
#include "reader.h"

static const char *const xyz[] = {"x", "y", "z", NULL};
static const char *const section_names[] = {"N", "Vy", "Vz", "T", "My", "Mz", NULL};

/* the body, which must be flexible; false when it is not (reported) */
static bool parse_flex_body(mapping *m, ir_output *o) {
  reader *r = m->r;
  get_ref(m, "body", NAME_BODY, true, &o->body, NULL);
  if (o->kind == OUT_DEFLECTION || o->kind == OUT_SECTION)
    get_choice(m, "component", "component", o->kind == OUT_SECTION ? section_names : xyz, false,
               &o->component);
  if (o->body >= 0 && r->model->bodies[o->body].kind != BODY_FLEXIBLE) {
    error_at(r, m->loc, "%s output '%s' needs a flexible body ('%s' is not)", output_element(o->kind)->type,
             o->name ? o->name : "?", r->model->bodies[o->body].name);
    return false;
  }
  return true;
}

/* after the kind's fields: the body must be flexible (and have the mode) */
static int check_flex_body(lmodel *L, const ir_output *o, const mb_outputdef *d) {
  if (d->body < 0 || L->body[d->body].kind != MB_BODY_FLEXIBLE ||
      (o->kind == OUT_MODAL && o->mode >= L->body[d->body].nm)) {
    diag_error(L->ir->path, o->loc, "output '%s' needs a flexible body%s", o->name,
               o->kind == OUT_MODAL ? " with that many modes" : "");
    return -1;
  }
  return 0;
}

/* --- deflection ------------------------------------------------------------- */

static void parse_deflection(mapping *m, ir_output *o) {
  reader *r = m->r;
  if (!parse_flex_body(m, o) || o->body < 0) return;
  const ir_body *b = &r->model->bodies[o->body];
  yaml_node_t *nd = map_require(m, "node", true, "a node number");
  if (nd != NULL) o->node = to_fe_node(r, nd, b);
  yaml_node_t *ch = map_get(m, "chord");
  if (ch != NULL) {
    if (ch->type != YAML_SEQUENCE_NODE || seq_length(ch) != 2)
      error_at(r, loc_of(ch), "'chord': expected [K0, K1], two node numbers");
    else
      for (int i = 0; i < 2; i++) o->chord[i] = to_fe_node(r, seq_item(r, ch, i), b);
  }
}

static int lower_deflection(lmodel *L, const ir_output *o, const int *jm0, const int *jm1, mb_outputdef *d) {
  (void)jm0, (void)jm1;
  d->node = o->node;
  d->chord[0] = o->chord[0];
  d->chord[1] = o->chord[1];
  return check_flex_body(L, o, d);
}

/* --- modal coordinate -------------------------------------------------------- */

static void parse_modal(mapping *m, ir_output *o) {
  reader *r = m->r;
  if (!parse_flex_body(m, o)) return;
  double mode;
  if (get_positive(m, "mode", true, &mode)) {
    if (mode != floor(mode) || mode > LIMIT_COUNT)
      error_at(r, m->last_loc, "'mode' must be a mode number (1, 2, ... up to %g)", LIMIT_COUNT);
    else
      o->mode = (int)mode - 1;
  }
}

static int lower_modal(lmodel *L, const ir_output *o, const int *jm0, const int *jm1, mb_outputdef *d) {
  (void)jm0, (void)jm1;
  d->node = o->mode;
  return check_flex_body(L, o, d);
}

/* --- section forces and stress ---------------------------------------------- */

static void parse_section_output(mapping *m, ir_output *o) {
  reader *r = m->r;
  if (!parse_flex_body(m, o) || o->body < 0) return;
  const ir_flex *fx = r->model->bodies[o->body].flex;
  double e = -1;
  if (get_number(m, "element", true, &e)) {
    o->element = -1;
    if (fx && fx->nodes && e == floor(e))
      for (int i = 0; i < fx->nbeams; i++)
        if ((fx->beam_ids ? fx->beam_ids[i] : i) == (long)e) o->element = i;
    if (o->element < 0)
      error_at(r, m->last_loc, "body '%s' has no beam %g (%s)", r->model->bodies[o->body].name, e,
               fx && fx->beam_ids ? "elements by their ids in the FE file" : "beams are numbered from 0");
  }
  static const char *const end_names[] = {"A", "B", NULL};
  get_choice(m, "end", "element end", end_names, false, &o->end);
  yaml_node_t *fb = map_get(m, "fiber");
  if (fb != NULL) {
    o->has_fiber = to_vector(r, fb, "'fiber'", 2, o->fiber);
    if (map_has(m, "component")) error_at(r, loc_of(fb), "give either 'fiber' (a stress) or 'component'");
  }
}

/* a SECTION output's rows of coefficients on w, appended to L->output_coef */
static int section_coefficients(lmodel *L, const ir_output *o, mb_outputdef *d) {
  const ir_body *B = &L->ir->bodies[o->body];
  const fe_modes *fm = &L->modes[d->body];
  int nm = L->body[d->body].nm;
  double rows[6 * MB_MAX_MODES + 1], sec[3];
  char err[256];
  if (!B->flex->nodes || !B->flex->beams) {
    diag_error(L->ir->path, o->loc, "output '%s': body '%s' has no beam elements (a modal data file)", o->name,
               B->name);
    return -1;
  }
  if (fe_section_rows(B->flex, o->element, o->end, fm, rows, sec, err, sizeof err)) {
    diag_error(L->ir->path, o->loc, "output '%s': %s", o->name, err);
    return -1;
  }
  double *c = realloc(L->output_coef, sizeof(double) * (size_t)(L->noutput_coef + 6 * nm + 1));
  if (!c) return -1;
  L->output_coef = c;
  d->node = L->noutput_coef;
  double *dst = c + L->noutput_coef;
  if (o->has_fiber) { /* sigma = N / A - Mz y / Iz + My z / Iy */
    for (int j = 0; j < nm; j++)
      dst[j] = rows[j] / sec[0] - (sec[2] > 0 ? rows[5 * nm + j] * o->fiber[0] / sec[2] : 0) +
               (sec[1] > 0 ? rows[4 * nm + j] * o->fiber[1] / sec[1] : 0);
    L->noutput_coef += nm;
  } else if (o->component >= 0) {
    memcpy(dst, rows + (size_t)o->component * nm, sizeof(double) * (size_t)nm);
    L->noutput_coef += nm;
  } else {
    memcpy(dst, rows, sizeof(double) * 6 * (size_t)nm);
    L->noutput_coef += 6 * nm;
  }
  /* the rows are the columns; the component says what they are (their unit
     in CSV.units): -1 all six resultants, 0..5 one of them, 6 the stress */
  d->component = o->has_fiber ? 6 : o->component;
  return 0;
}

static int lower_section(lmodel *L, const ir_output *o, const int *jm0, const int *jm1, mb_outputdef *d) {
  (void)jm0, (void)jm1;
  if (d->body >= 0 && L->body[d->body].kind == MB_BODY_FLEXIBLE && section_coefficients(L, o, d)) return -1;
  return check_flex_body(L, o, d);
}

/* --- the descriptors -------------------------------------------------------- */

static const char *const deflection_keys[] = {"name", "type", "body", "component", "node", "chord", "scale", NULL};
static const char *const modal_keys[] = {"name", "type", "body", "mode", "scale", NULL};
static const char *const section_keys[] = {"name", "type", "body", "component", "element", "end", "fiber",
                                           "scale", NULL};

const output_desc element_out_deflection = {
    .family = ELEMENT_OUTPUT, .type = "deflection", .ir_kind = OUT_DEFLECTION,
    OUTPUT_RUNTIME_KIND(MB_OUT_DEFLECTION), .keys = deflection_keys, .columns = xyz,
    .parse = parse_deflection, .lower = lower_deflection};
const output_desc element_out_modal = {
    .family = ELEMENT_OUTPUT, .type = "modal", .ir_kind = OUT_MODAL,
    OUTPUT_RUNTIME_KIND(MB_OUT_MODAL), .keys = modal_keys, .parse = parse_modal, .lower = lower_modal};
const output_desc element_out_section = {
    .family = ELEMENT_OUTPUT, .type = "section", .ir_kind = OUT_SECTION,
    OUTPUT_RUNTIME_KIND(MB_OUT_SECTION), .keys = section_keys, .columns = section_names,
    .parse = parse_section_output, .lower = lower_section};
