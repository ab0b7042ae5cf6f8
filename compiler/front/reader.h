/* reader.h: what the element parsers of compiler/elements/ use from the
 * document walk (reader.c) besides the typed YAML layer (yaml_map.h). */
#ifndef MBCC_READER_H
#define MBCC_READER_H

#include "yaml_map.h"

/* whether the element is given on FE nodes ('node' / 'nodes'; true also when
 * the nodes given were wrong: that was reported, and the point is then not required) */
bool fe_nodes_given(mapping *m, const int body[2], int node[2]);
/* the point of each side on a node: the node's position (a point given as
 * well must coincide with it) */
void check_node_point(reader *r, const ir_model *model, ir_loc loc, const int body[2],
                      const int node[2], bool point_given, double *point);
/* a time function ('scale', 'motion') */
void parse_profile(reader *r, yaml_node_t *n, const char *label, ir_profile *p);
/* a beam's section and material keys, on top of the defaults in *proto */
void parse_beam_properties(reader *r, mapping *body, ir_beam *proto);
extern const char *const theory_names[]; /* 'theory' of a beam */

/* A YAML file that the model names (fe_file: X.fe.yaml, modal_file): read
 * within the limits of a model file (its size, the bracket depth) and parsed
 * into *doc.  False after an error: reported at its place in the file, or,
 * with *unreadable set and errno saying why (EFBIG: too large), left to the
 * caller to report. */
bool load_named_yaml(const char *path, yaml_document_t *doc, bool *unreadable);
/* a file name given in the model, relative to the model file's directory */
char *model_relative_path(reader *r, const yaml_node_t *n);
/* a superelement's FE model from 'fe_file' and its 'interface' nodes (2 or
   more, *nodes allocated; compiler/elements/force_field.c); node positions global */
bool read_superelement_fe(mapping *m, const char *owner, ir_flex *fx, int **nodes, int *count);
/* one entry of the top-level 'roads' (compiler/elements/force_tyre.c) */
void parse_road(reader *r, yaml_node_t *key, yaml_node_t *value);
/* the components of a tyre output, NULL-terminated (output_element.c) */
extern const char *const tyre_component_names[];
/* FE node n of flexible body b (a number, a GRID id or a name of
   'node_names'), or -1 after an error at n */
int to_fe_node(reader *r, yaml_node_t *n, const ir_body *b);

/* what the scenes (scene.c) reuse: a flexible body's modal settings, the
   outputs list (a scene replaces it), freeing outputs */
void parse_modal_settings(mapping *m, ir_flex *fx);
void parse_outputs(reader *r, yaml_node_t *n, name_table *scene_outputs,
                   ir_output **outputs, int *count);
void free_outputs(ir_output *outputs, int count);
void free_flex(ir_flex *fx);

/* shared by reader.c and flexible_body.c: the flexible body's keys (a body of
   type 'flexible'), the global position of node k of flexible body b, a file
   read whole within a size limit (NULL, errno set, after a failure), and a
   libyaml parser error reported at its place in data */
void parse_flexible_body(mapping *m, ir_body *b, ir_loc type_loc);
void fe_node_global(const ir_body *b, int k, double out[3]);
char *read_text_file(const char *path, size_t *size, double limit);
void report_yaml_error(const char *path, const yaml_parser_t *parser, const char *data, size_t size);

#endif
