/* output_motion.c: the outputs of a body's (or a point's) motion: position,
 * orientation, angle, velocity, angular velocity, acceleration, angular
 * acceleration, and the motion of one marker relative to another (kernel:
 * mb_model_outputs, runtime/core/model_generic.c). */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "element.h"
#include "reader.h"

static const char *const xyz[] = {"x", "y", "z", NULL};

/* 'node' of a position, velocity or acceleration output: on a flexible body,
 * instead of a 'point' */
static void parse_point_or_node(mapping *m, ir_output *o) {
  reader *r = m->r;
  o->has_point = get_vector(m, "point", 3, false, o->point);
  if (map_has(m, "node") && o->body >= 0) {
    const ir_body *b = &r->model->bodies[o->body];
    yaml_node_t *nd = map_get(m, "node");
    if (b->kind != BODY_FLEXIBLE)
      error_at(r, loc_of(nd), "'node' needs a flexible body ('%s' is not)", b->name);
    else if (o->has_point)
      error_at(r, loc_of(nd), "give either 'point' or 'node', not both");
    else
      o->node = to_fe_node(r, nd, b);
  }
}

/* position, velocity, acceleration: of the body frame, a point or a node */
static void parse_point_motion(mapping *m, ir_output *o) {
  get_ref(m, "body", NAME_BODY, true, &o->body, NULL);
  parse_point_or_node(m, o);
  get_choice(m, "component", "component", xyz, false, &o->component);
}

/* angular velocity and acceleration */
static void parse_body_motion(mapping *m, ir_output *o) {
  get_ref(m, "body", NAME_BODY, true, &o->body, NULL);
  get_choice(m, "component", "component", xyz, false, &o->component);
}

static void parse_orientation(mapping *m, ir_output *o) {
  get_ref(m, "body", NAME_BODY, true, &o->body, NULL);
}

static void parse_angle(mapping *m, ir_output *o) {
  get_ref(m, "body", NAME_BODY, true, &o->body, NULL);
  get_axis(m, "axis", true, o->axis);
}

static int lower_point_motion(lmodel *L, const ir_output *o, const int *jm0, const int *jm1,
                              mb_outputdef *d) {
  (void)L, (void)jm0, (void)jm1;
  d->node = o->node;
  return 0;
}

/* any unit vector perpendicular to a */
static void perpendicular(const double a[3], double u[3]) {
  int k = 0;
  for (int j = 1; j < 3; j++)
    if (fabs(a[j]) < fabs(a[k])) k = j;
  double e[3] = {0, 0, 0};
  e[k] = 1;
  double d = mb_dot3(e, a);
  for (int j = 0; j < 3; j++) u[j] = e[j] - d * a[j];
  double n = sqrt(mb_dot3(u, u));
  for (int j = 0; j < 3; j++) u[j] /= n;
}

/* the axis and a reference direction across it, global and in body axes */
static int lower_angle(lmodel *L, const ir_output *o, const int *jm0, const int *jm1, mb_outputdef *d) {
  (void)jm0, (void)jm1;
  if (d->body < 0) return 0;
  const ir_body *B = &L->ir->bodies[o->body];
  double A[9];
  mb_euler_to_A(B->orientation, A);
  memcpy(d->axis_g, o->axis, sizeof d->axis_g);
  perpendicular(o->axis, d->u_g);
  mb_mul3t(A, d->axis_g, d->axis);
  mb_mul3t(A, d->u_g, d->u);
  return 0;
}

/* --- relative: a marker measured from another ----------------------------- */

/* A marker of a relative output: 'body' with an optional 'point' (global at
 * t = 0) or FE 'node' (flexible bodies), in mapping m. */
static void get_output_marker(reader *r, mapping *m, bool required, int *body, bool *has_point,
                              double point[3], int *node) {
  if (!get_ref(m, "body", NAME_BODY, required, body, NULL)) return;
  *has_point = get_vector(m, "point", 3, false, point);
  yaml_node_t *nd = map_get(m, "node");
  if (nd == NULL) return;
  const ir_body *b = &r->model->bodies[*body];
  if (b->kind != BODY_FLEXIBLE)
    error_at(r, loc_of(nd), "'node' needs a flexible body ('%s' is not)", b->name);
  else if (*has_point)
    error_at(r, loc_of(nd), "give either 'point' or 'node', not both");
  else
    *node = to_fe_node(r, nd, b);
}

static void parse_relative(mapping *m, ir_output *o) {
  static const char *const displacement_names[] = {"displacement", "velocity", "acceleration", NULL};
  reader *r = m->r;
  int choice = 0;
  if (get_choice(m, "quantity", "quantity", displacement_names, false, &choice))
    o->quantity = (ir_quantity)choice;
  get_output_marker(r, m, true, &o->body, &o->has_point, o->point, &o->node);
  yaml_node_t *rel = map_get(m, "relative_to");
  if (rel != NULL) {
    static const char *const marker_keys[] = {"body", "point", "node", NULL};
    mapping sub;
    if (map_open(&sub, r, rel, loc_of(rel), "'relative_to' of output '%s'", o->name ? o->name : "?")) {
      map_check_keys(&sub, marker_keys);
      get_output_marker(r, &sub, true, &o->rel_body, &o->rel_has_point, o->rel_point, &o->rel_node);
    }
    map_close(&sub);
  }
  yaml_node_t *fr = map_get(m, "frame");
  if (fr != NULL && !(fr->type == YAML_SCALAR_NODE && scalar_equals(fr, "global"))) {
    int b = resolve_name(r, fr, NAME_BODY, "frame");
    if (b >= 0) o->frame_body = b;
  }
  get_choice(m, "component", "component", xyz, false, &o->component);
}

static int lower_relative(lmodel *L, const ir_output *o, const int *jm0, const int *jm1, mb_outputdef *d) {
  (void)jm0, (void)jm1;
  const ir_model *ir = L->ir;
  output_measure_init(d, o);
  if (d->body < 0 && o->has_point) memcpy(d->s, o->point, sizeof d->s);
  d->node = o->node;
  d->body2 = o->rel_body - 1;
  d->node2 = o->rel_node;
  if (o->rel_has_point && d->body2 < 0) {
    memcpy(d->s2, o->rel_point, sizeof d->s2);
  } else if (o->rel_has_point) {
    const ir_body *B = &ir->bodies[o->rel_body];
    double A[9], rel[3];
    mb_euler_to_A(B->orientation, A);
    for (int j = 0; j < 3; j++) rel[j] = o->rel_point[j] - B->position[j];
    mb_mul3t(A, rel, d->s2);
  }
  d->frame = o->frame_body - 1;
  return 0;
}

/* --- the descriptors -------------------------------------------------------- */

static const char *const point_keys[] = {"name", "type", "body", "point", "node", "component", "scale", NULL};
static const char *const body_keys[] = {"name", "type", "body", "component", "scale", NULL};
static const char *const orientation_keys[] = {"name", "type", "body", "scale", NULL};
static const char *const angle_keys[] = {"name", "type", "body", "axis", "scale", NULL};
static const char *const relative_keys[] = {"name", "type", "quantity", "body", "point", "node",
                                            "relative_to", "frame", "component", "scale", NULL};
static const char *const euler_parameters[] = {"e0", "e1", "e2", "e3", NULL};

const output_desc element_out_position = {
    .family = ELEMENT_OUTPUT, .type = "position", .ir_kind = OUT_POSITION,
    OUTPUT_RUNTIME_KIND(MB_OUT_POSITION), .keys = point_keys, .columns = xyz,
    .parse = parse_point_motion, .lower = lower_point_motion};
const output_desc element_out_orientation = {
    .family = ELEMENT_OUTPUT, .type = "orientation", .ir_kind = OUT_ORIENTATION,
    OUTPUT_RUNTIME_KIND(MB_OUT_ORIENTATION), .keys = orientation_keys, .columns = euler_parameters,
    .parse = parse_orientation};
const output_desc element_out_angle = {
    .family = ELEMENT_OUTPUT, .type = "angle", .ir_kind = OUT_ANGLE,
    OUTPUT_RUNTIME_KIND(MB_OUT_ANGLE), .keys = angle_keys, .parse = parse_angle, .lower = lower_angle};
const output_desc element_out_velocity = {
    .family = ELEMENT_OUTPUT, .type = "velocity", .ir_kind = OUT_VELOCITY,
    OUTPUT_RUNTIME_KIND(MB_OUT_VELOCITY), .keys = point_keys, .columns = xyz,
    .parse = parse_point_motion, .lower = lower_point_motion};
const output_desc element_out_angular_velocity = {
    .family = ELEMENT_OUTPUT, .type = "angular_velocity", .ir_kind = OUT_ANGULAR_VELOCITY,
    OUTPUT_RUNTIME_KIND(MB_OUT_ANGULAR_VELOCITY), .keys = body_keys, .columns = xyz,
    .parse = parse_body_motion};
const output_desc element_out_acceleration = {
    .family = ELEMENT_OUTPUT, .type = "acceleration", .ir_kind = OUT_ACCELERATION,
    OUTPUT_RUNTIME_KIND(MB_OUT_ACCELERATION), .keys = point_keys, .columns = xyz,
    .parse = parse_point_motion, .lower = lower_point_motion};
const output_desc element_out_angular_acceleration = {
    .family = ELEMENT_OUTPUT, .type = "angular_acceleration", .ir_kind = OUT_ANGULAR_ACCELERATION,
    OUTPUT_RUNTIME_KIND(MB_OUT_ANGULAR_ACCELERATION), .keys = body_keys, .columns = xyz,
    .parse = parse_body_motion};
const output_desc element_out_relative = {
    .family = ELEMENT_OUTPUT, .type = "relative", .ir_kind = OUT_RELATIVE,
    OUTPUT_RUNTIME_KIND(MB_OUT_RELATIVE), .keys = relative_keys, .columns = xyz,
    .parse = parse_relative, .lower = lower_relative};
