/* params.h: the model's 'parameters:' block and arithmetic expressions over
 * parameters in numeric fields (params.c).  docs/model-format.md, Parameters. */
#ifndef MBCC_PARAMS_H
#define MBCC_PARAMS_H

#include <stdio.h>

#include "ir.h"
#include "yaml_map.h"

/* Reads 'parameters:' (n may be NULL) into r->model->params; values are
 * evaluated on first use and all of them at the end of this call. */
void parse_parameters(reader *r, yaml_node_t *n);

/* A scalar that is not a plain number, as an expression: 1 with *out set,
 * -1 after reporting at the offending character ('label' names the field),
 * 0 when it is no expression and nothing was reported (without a
 * 'parameters:' block a syntax error or unknown name is left to the caller,
 * which says "must be a number"). */
int expr_number(reader *r, yaml_node_t *n, const char *label, double *out);

/* *value, the number written in scalar n, as the subsystem instances placed
 * n (compose.h): negated if mirrored, then moved by the offsets of their
 * 'position'; false after reporting (at the offset, or at n) */
bool params_place(reader *r, const yaml_node_t *n, const char *label, double *value);

/* --set NAME=VALUE for the next ir_read: run-time parameters take these
 * values instead of their defaults (the arrays must outlive the reads). */
void params_set_overrides(const char *const *names, const double *values, int count);

/* The index of parameter 'name', or -1; 'suggest' (may be NULL) gets a
 * close name for "did you mean", or "". */
int params_find(const ir_model *m, const char *name, char *suggest, size_t size);

/* the expression as C over the run-time parameter vector 'vector' (p[i] for
 * run-time parameter i, in the order of run-time parameters among params) */
void expr_print_c(FILE *f, const ir_model *m, const ir_expr *e, const char *vector);
/* the expression's value with run-time parameter i at p[i] (as the
 * generated code computes it; NaN out of a function's domain) */
double expr_eval_runtime(const ir_model *m, const ir_expr *e, const double *p);
/* index among run-time parameters of params[k], or -1 */
int params_runtime_index(const ir_model *m, int k);
/* whether e names params[k] directly */
bool expr_names(const ir_expr *e, int k);

/* The field at 'loc' (if written as an expression over parameters) obeys
 * 'rule': recorded in its use (ir_expr_use.rule) for run-time values. */
void params_note_rule(reader *r, ir_loc loc, ir_value_rule rule, const char *field);
/* " must be >= 0" and the like, "" for RULE_ANY */
const char *params_rule_text(ir_value_rule rule);
/* whether v obeys the rule */
bool params_rule_holds(ir_value_rule rule, double v);

void params_free(ir_model *m);

#endif
