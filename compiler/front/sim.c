/* sim.c: the simulation settings: defaults, the base 'simulation' mapping,
 * a scene's overrides, and the merge with derived defaults (sim.h). */
#include "sim.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

/* ---------------------------------------------------------------------------
 * simulation settings: a base mapping and per-scene overrides
 * ------------------------------------------------------------------------- */


static const char *const sim_keys[SIM_FIELDS] = {
    "end_time", "output_step", "step",       "rtol",          "atol",
    "min_step", "max_step",    "alpha",      "beta",          "rho_inf",   "integrator",
    "solver",   "stabilization", "joints_on_flexible", "equilibrium"};

static const char *const integrator_names[] = {"rk4", "dopri5", "genalpha", "auto", NULL};
static const char *const solver_names[] = {"klu", "dense", "ldl", NULL};
static const char *const stabilization_names[] = {"projection", "baumgarte", "none", NULL};
static const char *const jof_names[] = {"direct", "virtual", NULL};
static const char *const flag_names[] = {"false", "true", NULL};

void sim_defaults(sim_settings *s) {
  memset(s, 0, sizeof *s);
  s->value[SIM_END_TIME] = 1;
  s->value[SIM_RTOL] = 1e-6;
  s->value[SIM_ATOL] = 1e-8;
  s->value[SIM_MIN_STEP] = 1e-12;
  s->value[SIM_ALPHA] = 10;
  s->value[SIM_BETA] = 10;
  s->value[SIM_RHO_INF] = 0.8;
  s->value[SIM_INTEGRATOR] = INTEGRATOR_DOPRI5;
  s->value[SIM_SOLVER] = SOLVER_LDL;
  s->value[SIM_STABILIZATION] = STAB_PROJECTION;
  s->value[SIM_JOINTS_ON_FLEXIBLE] = JOF_DIRECT;
}

static void sim_set(sim_settings *s, int field, double value, sim_source source, ir_loc loc) {
  s->value[field] = value;
  s->source[field] = source;
  s->loc[field] = loc;
}

/* Only the keys given change 's'. */
void parse_sim(reader *r, yaml_node_t *n, const char *what, sim_source source,
               sim_settings *s) {
  mapping m;
  if (!map_open(&m, r, n, loc_of(n), "%s", what))
    return;
  static const char *const keys[] = {"end_time",  "output_step", "step",
                                     "rtol",      "atol",        "min_step",
                                     "max_step",  "integrator",  "solver",
                                     "stabilization", "baumgarte", "joints_on_flexible",
                                     "rho_inf", "equilibrium", NULL};
  map_check_keys(&m, keys);
  for (int field = SIM_END_TIME; field <= SIM_MAX_STEP; field++) {
    double value;
    if (get_positive(&m, sim_keys[field], false, &value))
      sim_set(s, field, value, source, m.last_loc);
  }
  double rho_inf;
  if (get_nonnegative(&m, "rho_inf", false, &rho_inf)) {
    if (rho_inf > 1)
      error_at(r, m.last_loc, "'rho_inf' of %s must be from 0 to 1 (the spectral radius of the "
               "generalized-alpha method at an infinite step), got %g", what, rho_inf);
    else
      sim_set(s, SIM_RHO_INF, rho_inf, source, m.last_loc);
  }
  yaml_node_t *baumgarte = map_get(&m, "baumgarte");
  if (baumgarte != NULL) {
    mapping b;
    if (map_open(&b, r, baumgarte, loc_of(baumgarte), "'baumgarte' of %s", what)) {
      static const char *const gains[] = {"alpha", "beta", NULL};
      map_check_keys(&b, gains);
      for (int field = SIM_ALPHA; field <= SIM_BETA; field++) {
        double value;
        if (get_nonnegative(&b, sim_keys[field], false, &value))
          sim_set(s, field, value, source, b.last_loc);
      }
    }
    map_close(&b);
  }
  static const char *const *const choices[] = {integrator_names, solver_names,
                                               stabilization_names, jof_names, flag_names};
  yaml_node_t *jof = map_get(&m, "joints_on_flexible");
  if (jof != NULL && jof->type == YAML_SEQUENCE_NODE) {
    s->jof_list = jof;
    sim_set(s, SIM_JOINTS_ON_FLEXIBLE, JOF_LIST, source, loc_of(jof));
  } else if (jof != NULL) {
    s->jof_list = NULL;
  }
  for (int field = SIM_INTEGRATOR; field < SIM_FIELDS; field++) {
    int choice;
    if (field == SIM_JOINTS_ON_FLEXIBLE && jof != NULL && jof->type == YAML_SEQUENCE_NODE)
      continue;
    if (get_choice(&m, sim_keys[field], sim_keys[field], choices[field - SIM_INTEGRATOR], false,
                   &choice))
      sim_set(s, field, choice, source, m.last_loc);
  }
  map_close(&m);
}

/* Fills derived defaults and checks the settings against each other.  For a
 * scene only conflicts that involve its own keys are reported: the others
 * were reported for the base settings already. */
bool sim_finish(reader *r, sim_settings *s, bool is_scene, ir_sim *out) {
  double *v = s->value;
  if (s->source[SIM_OUTPUT_STEP] == FROM_DEFAULT)
    sim_set(s, SIM_OUTPUT_STEP, v[SIM_END_TIME] / 100, s->source[SIM_END_TIME], s->loc[SIM_END_TIME]);
  if (s->source[SIM_STEP] == FROM_DEFAULT)
    sim_set(s, SIM_STEP, v[SIM_OUTPUT_STEP] / 10, s->source[SIM_OUTPUT_STEP],
            s->loc[SIM_OUTPUT_STEP]);
  /* the error control alone decides the step (dense output serves the output
     times): the largest step is the whole run unless given */
  if (s->source[SIM_MAX_STEP] == FROM_DEFAULT)
    sim_set(s, SIM_MAX_STEP, v[SIM_END_TIME], s->source[SIM_END_TIME], s->loc[SIM_END_TIME]);

  static const int smaller[][2] = {{SIM_OUTPUT_STEP, SIM_END_TIME}, {SIM_MIN_STEP, SIM_MAX_STEP}};
  bool ok = true;
  for (size_t i = 0; i < sizeof smaller / sizeof smaller[0]; i++) {
    int a = smaller[i][0], b = smaller[i][1];
    if (v[a] <= v[b])
      continue;
    int blamed = s->source[a] >= s->source[b] ? a : b;
    if (is_scene && s->source[blamed] != FROM_SCENE)
      continue;
    error_at(r, s->source[blamed] == FROM_DEFAULT ? file_start : s->loc[blamed],
             "'%s' (%g) must not be larger than '%s' (%g)", sim_keys[a], v[a], sim_keys[b], v[b]);
    ok = false;
  }
  out->end_time = v[SIM_END_TIME];
  out->output_step = v[SIM_OUTPUT_STEP];
  out->step = v[SIM_STEP];
  out->rtol = v[SIM_RTOL];
  out->atol = v[SIM_ATOL];
  out->min_step = v[SIM_MIN_STEP];
  out->max_step = v[SIM_MAX_STEP];
  out->baumgarte_alpha = v[SIM_ALPHA];
  out->baumgarte_beta = v[SIM_BETA];
  out->rho_inf = v[SIM_RHO_INF];
  out->integrator = (ir_integrator)(int)v[SIM_INTEGRATOR];
  out->solver = (ir_solver)(int)v[SIM_SOLVER];
  out->stabilization = (ir_stab)(int)v[SIM_STABILIZATION];
  out->joints_on_flexible = (ir_jof)(int)v[SIM_JOINTS_ON_FLEXIBLE];
  out->equilibrium = v[SIM_EQUILIBRIUM] != 0;
  return ok;
}

