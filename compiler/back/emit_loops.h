/* emit_loops.h: the loop form of the emitted evaluation (emit_loops.c).
 * Identical elements (rigid bodies of the same mass and inertia, joints whose
 * rows have the same primitives, sides and pattern) form a group; a group is
 * one static const table of its members (designated initializers: the
 * indices of their bodies and markers, their rows, the slots of K where
 * their entries go) and one loop that calls the runtime's kernels (those of
 * the generic path) for each member and scatters the results at the table's
 * slots.  The straight-line form writes every element out with its
 * constants folded: fast per call, but gcc's time grows with every element. */
#ifndef MBCC_EMIT_LOOPS_H
#define MBCC_EMIT_LOOPS_H

#include <stdio.h>

#include "lower.h"

/* G: a model's evaluation takes the loop form when its largest group has at
 * least this many members (MBCC_LOOP_MIN=N overrides it, for measurement and
 * tests: 0 takes the loop form whenever the model has one) */
int loop_min_group(void);

/* The elements the loop form writes (1) and those it leaves to the
 * straight-line code (0): a flexible body, a marker on one, a force element
 * without a loop form (a superelement) or on such a marker, a joint with a
 * row on such a marker.  Frames and markers of the looped elements are in
 * the arrays fr[] and mk[]; the straight-line code reads the ones it needs
 * from there (emit.c). */
typedef struct {
  unsigned char *body, *marker, *force, *row;
  int mixed; /* some element is written straight-line */
} loop_choice;

/* 1 when the evaluation of L takes the loop form: the largest group of its
 * elements that have one has at least loop_min_group() members (c says
 * which; loop_choice_free releases it); 0: straight-line as a whole (c
 * empty); -1 out of memory */
int emit_loops_choose(const lmodel *L, loop_choice *c);
void loop_choice_free(loop_choice *c);

/* the loop form of the elements c loops: the groups' tables to 'tables'
 * (file scope, before the evaluation), the evaluation's body (its loops) to
 * 'body'.  0, or -1 out of memory. */
int emit_loops_eval(FILE *tables, FILE *body, const lmodel *L, const loop_choice *c);

/* init's statements after K is zeroed, when the evaluation is in the loop
 * form: the mass blocks and the rows' constant entries as loops over the
 * model's tables (bodies[], rows[]) */
void emit_loops_init(FILE *f, const lmodel *L);

#endif
