/* emit_split.h: the generated evaluation split into functions of bounded size
 * (emit_split.c).  emit_eval writes its body into an eval_split's memory
 * stream and marks the boundaries between elements (a frame, a marker, a body
 * force, a force element, a row); eval_split_finish writes the body either as
 * one function, as before, or, when it is large, as parts of about
 * eval_part_bytes() each plus a function that calls them in order. */
#ifndef MBCC_EMIT_SPLIT_H
#define MBCC_EMIT_SPLIT_H

#include <stdio.h>

typedef struct {
  FILE *body;  /* where emit_eval writes the function body */
  char *text;  /* the body's text once closed */
  size_t len;
  long *mark;  /* offsets where a part may start, ascending */
  char **label; /* what starts there (a comment text) */
  int nmark, cap;
  int failed;
  int one_function; /* marks are ignored: the body stays one function (a mixed
                       loop form's arrays fr[] and mk[] cross any cut) */
} eval_split;

/* open the body stream; 0, or -1 out of memory */
int eval_split_begin(eval_split *s);
/* the text written from here on belongs to a new element 'label' (printf style) */
void eval_split_mark(eval_split *s, const char *fmt, ...);
/* a new element 'label' at each line written since offset 'from' that starts
 * with 'prefix' (a block of independent statements, e.g. one per pair of
 * bodies, that may go to different parts) */
void eval_split_mark_lines(eval_split *s, long from, const char *prefix, const char *label);
/* a size setting of the emitters: the environment variable 'env' when it is
 * a whole number >= 0 (for measurement and tests), else 'fallback' */
long emit_size_setting(const char *env, long fallback);
/* about this many bytes of body text per part; the body is split when it is
 * larger than two parts (MBCC_EVAL_PART_BYTES overrides it, for measurement) */
long eval_part_bytes(void);
/* what one call of an inlined runtime kernel weighs in that budget, in bytes
 * (MBCC_EVAL_CALL_BYTES overrides it, for measurement) */
long eval_call_bytes(void);
/* Where the parts go when they are compiled as translation units of their
 * own (emit_files.c): the shared struct and the parts' prototypes into
 * 'header' (the private header 'header_name', which 'out' then includes), part
 * p of n into the stream part_file returns (NULL: failure). */
typedef struct {
  FILE *header;
  const char *header_name;
  FILE *(*part_file)(void *ctx, int part, int nparts);
  void *ctx;
} eval_files;

/* write the evaluation 'nm'_eval to out: 'head' is the monolithic function's
 * signature and locals (written as they were before the split); the parts get
 * the same scratch locals.  With files (may be NULL) a split evaluation's
 * parts go there instead of into out.  Returns the number of parts (1: one
 * function), or -1 out of memory.  Frees s. */
int eval_split_finish(eval_split *s, FILE *out, const char *nm, const char *head, const eval_files *files);

#endif
