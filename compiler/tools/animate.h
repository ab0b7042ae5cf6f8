/* animate.h: `mbcc animate` and `mbcc run --animate`: one self-contained HTML
 * page (three.js and the data inlined) that plays a result's motion. */
#ifndef MBCC_ANIMATE_H
#define MBCC_ANIMATE_H

#include <stddef.h>

#include "ir.h"

/* Append the outputs the animation reads to the model: every body's position
 * ("body.<name>.r", 3 columns) and Euler parameters ("body.<name>.p", 4), and
 * each modal coordinate of a flexible body ("body.<name>.w<j>").  0, or 2
 * after reporting. */
int animate_add_pose_outputs(ir_model *ir);

/* Write the page 'html' from the CSV 'csv' (which holds the pose columns)
 * and, when 'model' is not NULL, the geometry of that model (and 'scene'):
 * joint and marker points, shapes, FE nodes, beams and mode shapes.
 * 'scale' multiplies the drawn deformation.  0, or 2 after reporting; nothing
 * is left half-written. */
int animate_write(const char *csv, const char *model, const char *scene, const char *html,
                  double scale, int quiet);

/* the page beside a CSV: its name with .html for .csv (or appended) */
void animate_page_name(const char *csv, char *html, size_t n);

/* mbcc animate results.csv [-m M.yaml] [--scene S] [-o out.html] [--scale S] [--quiet] */
int cmd_animate(int argc, char **argv);

#endif
