/* modal_file.h: a flexible body's modal data file (modal_file:,
 * docs/modal-file.md) read into the IR by the front end (modal_file.c). */
#ifndef MBCC_MODAL_FILE_H
#define MBCC_MODAL_FILE_H

#include "yaml_map.h"

/* Reads the modal data file that 'named' (the value of the model's
 * 'modal_file', a scalar) names for body b: fx->modal_file is its path and,
 * if it is valid, fx->modal its content.  Errors are reported where they are
 * in the file, with a note at 'named'. */
void read_modal_file(reader *r, const yaml_node_t *named, const ir_body *b, ir_flex *fx);
void free_modal_data(ir_modal_data *md);

#endif
