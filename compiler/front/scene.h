/* scene.h: scenes, named overrides of the base model (scene.c): parsing
 * every scene, and applying the chosen one after the model is read. */
#ifndef MBCC_SCENE_H
#define MBCC_SCENE_H

#include "sim.h"
#include "yaml_map.h"

void parse_scenes(reader *r, yaml_node_t *n, const sim_settings *base_sim,
                  const char *chosen);
void report_unknown_scene(reader *r, yaml_node_t *scenes, const char *chosen);
void mark_virtual_joints(reader *r, yaml_node_t *list);
void apply_scene(ir_model *model, chosen_scene *s);
/* after the flexible bodies are reduced: modes_of_body[b] modes of IR body b */
void scene_drop_modal_outputs(ir_model *model, const int *modes_of_body);
void scene_mark_pruned_uses(reader *r, yaml_node_t *root);
void free_chosen_scene(chosen_scene *s, int nbodies);

#endif
