/* sim.h: the simulation settings of a model and of its scenes (sim.c): a
 * base mapping and per-scene overrides, merged, with derived defaults. */
#ifndef MBCC_SIM_H
#define MBCC_SIM_H

#include "yaml_map.h"

enum {
  SIM_END_TIME,
  SIM_OUTPUT_STEP,
  SIM_STEP,
  SIM_RTOL,
  SIM_ATOL,
  SIM_MIN_STEP,
  SIM_MAX_STEP,
  SIM_ALPHA,
  SIM_BETA,
  SIM_RHO_INF,
  SIM_INTEGRATOR,
  SIM_SOLVER,
  SIM_STABILIZATION,
  SIM_JOINTS_ON_FLEXIBLE,
  SIM_EQUILIBRIUM,
  SIM_FIELDS
};

/* Where a setting came from: derived defaults are computed last, from the
 * merged values, and inherit the source of what they derive from. */
typedef enum { FROM_DEFAULT, FROM_BASE, FROM_SCENE } sim_source;

typedef struct {
  yaml_node_t *jof_list;    /* joints_on_flexible given as a list of joint names */
  double value[SIM_FIELDS]; /* choices hold their index */
  sim_source source[SIM_FIELDS];
  ir_loc loc[SIM_FIELDS];
} sim_settings;

void sim_defaults(sim_settings *s);
void parse_sim(reader *r, yaml_node_t *n, const char *what, sim_source source,
               sim_settings *s);
bool sim_finish(reader *r, sim_settings *s, bool is_scene, ir_sim *out);

#endif
